/* ===== >>geom : signed distances and closest points ================================================ */

/* Private helpers of the implementation (>>impl_geom), one copy for every user: closest points on
   segments and triangles, signed distances of boxes, spheres, discs, capped cylinders and polygons,
   distance gradients by central differences, the open fractions of cut grid faces. DEM walls, PIC
   obstacles and the couplers call them. */
