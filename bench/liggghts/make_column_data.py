#!/usr/bin/env python3
"""Write column.data: LIGGGHTS read_data file for the DEM column-collapse benchmark.

20 x 20 x 50 spheres, d = 2 mm, rho = 2500 kg/m^3, simple cubic lattice of spacing
2.1 mm with the first centre 1.05 mm from the walls at x = 0, y = 0, z = 0, every
coordinate jittered by a uniform random offset in [-0.05, +0.05] mm (fixed seed).
Box: 0.168 x 0.042 x 0.2 m (walls in the input script; top open).
Atom line format of atom_style granular: id type diameter density x y z.
Usage: python3 make_column_data.py [output] [seed]
"""
import random
import sys

NX, NY, NZ = 20, 20, 50
SPACING = 2.1e-3
FIRST = 1.05e-3
JITTER = 0.05e-3
DIAMETER = 2.0e-3
DENSITY = 2500.0
BOX = (0.168, 0.042, 0.2)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "column.data"
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 12345
    rng = random.Random(seed)
    n = NX * NY * NZ
    with open(out, "w") as f:
        f.write("LIGGGHTS data: granular column, %d spheres, seed %d\n\n" % (n, seed))
        f.write("%d atoms\n1 atom types\n\n" % n)
        f.write("0.0 %.6f xlo xhi\n0.0 %.6f ylo yhi\n0.0 %.6f zlo zhi\n\n" % BOX)
        f.write("Atoms\n\n")
        i = 1
        for k in range(NZ):
            for j in range(NY):
                for l in range(NX):
                    x = FIRST + l * SPACING + rng.uniform(-JITTER, JITTER)
                    y = FIRST + j * SPACING + rng.uniform(-JITTER, JITTER)
                    z = FIRST + k * SPACING + rng.uniform(-JITTER, JITTER)
                    f.write("%d 1 %.6g %.6g %.9e %.9e %.9e\n" % (i, DIAMETER, DENSITY, x, y, z))
                    i += 1


if __name__ == "__main__":
    main()
