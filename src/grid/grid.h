/* ===== >>grid : cell grid shared by DEM, MPS and the couplings ==================================== */

/* A uniform grid of cubic cells over a box; items (particle indices) are binned by a counting sort,
   so a build is O(n) and a query visits the 3^dim cells around a point. Positions outside the box
   are clamped into its border cells, so every item is found. The cell size is enlarged when the box
   would need more than `max_cells` cells, which keeps memory bounded for any domain. Along a
   periodic axis the cells tile the period exactly (a little wider than cell_size) and the
   neighbourhoods wrap round, so neighbours across the seam are found; with fewer than 3 cells along
   it the axis is one cell. The struct is public so solvers can embed it; treat its fields as
   read-only. */
typedef struct fsdem_cellgrid {
    int dim;                  /* 2 or 3 */
    fsdem_vec3 origin;        /* m, lower corner */
    fsdem_real cell_size;     /* m, edge of one cell (>= the requested size) */
    fsdem_real inv_cell_size; /* 1/m */
    fsdem_real inv_width[3];  /* 1/m, per axis: 1/cell_size, or cells per period along a periodic axis */
    int wrap[3];              /* 1: the neighbourhoods wrap round this (periodic) axis */
    int n[3];                 /* cells per axis (n[2] = 1 in 2D) */
    int cell_count;           /* n[0]*n[1]*n[2] */
    int *cell_start;          /* cell_count + 1 offsets into `items` */
    int *items;               /* item indices sorted by cell */
    int *cell_of;             /* cell of each item, as binned by the last build */
    int item_capacity, cell_capacity;
    fsdem_allocator allocator;
} fsdem_cellgrid;

/* Set up the grid geometry for the box [lo, hi] and a wanted cell size (m). `max_cells` caps the
   number of cells (0: 1<<24). Reuses memory already held. Returns FSDEM_ERR_INVALID_ARG for an empty
   box or a non-positive size, FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_cellgrid_setup(fsdem_cellgrid *grid, const fsdem_allocator *allocator,
                                            int dim, fsdem_vec3 lo, fsdem_vec3 hi,
                                            fsdem_real cell_size, int max_cells);
/* fsdem_cellgrid_setup with the axes a where periodic[a] != 0 periodic, of period hi - lo
   (periodic may be NULL: none). */
FSDEM_API fsdem_result fsdem_cellgrid_setup_periodic(fsdem_cellgrid *grid, const fsdem_allocator *allocator, int dim,
                                                     fsdem_vec3 lo, fsdem_vec3 hi, fsdem_real cell_size, int max_cells,
                                                     const int periodic[3]);
/* Bin `count` (>= 0) points. FSDEM_ERR_INVALID_ARG before a successful setup, for a negative count or
   NULL points; FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_cellgrid_build(fsdem_cellgrid *grid, const fsdem_vec3 *points,
                                            int count);
/* Cell holding a point (clamped into the grid) and its integer coordinates. */
FSDEM_API int fsdem_cellgrid_cell(const fsdem_cellgrid *grid, fsdem_vec3 p, int coord[3]);
/* Writes the cells of the 3^dim block around cell coordinates `coord` (those inside the grid) to
   `cells` (room for 27) and returns their number. */
FSDEM_API int fsdem_cellgrid_neighbourhood(const fsdem_cellgrid *grid, const int coord[3],
                                           int cells[27]);
/* The cell at `coord` and the neighbours after it in the 3^dim block (those inside the grid), into
   `cells` (room for 14), returning their number: visiting every cell against these finds each pair
   of neighbouring cells once. The cell itself comes first. */
FSDEM_API int fsdem_cellgrid_forward(const fsdem_cellgrid *grid, const int coord[3], int cells[14]);
/* Releases the memory; the struct may be set up again. */
FSDEM_API void fsdem_cellgrid_free(fsdem_cellgrid *grid);
