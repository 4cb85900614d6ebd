"""Runs PySPH's dam_break_2d example (WCSPH, Debian python3-pysph) as the PySPH side of
bench/mps_dambreak, times it and prints the front (largest x of a fluid particle) at t = 0.4 s and
t = 0.6 s from its output files.

Usage (see run_pysph.sh, which sets the interpreter and one thread):
    /usr/bin/python3 run_pysph.py [--stock] [--dx 0.015] [--tf 0.6] [--out DIR] [PySPH options]
Other options go to the PySPH application (e.g. --no-adaptive-timestep, --timestep 3.9e-5).

Geometry of the example (pysph/examples/dam_break_2d.py, read from the installed source): tank
4 m x 4 m open at the top, wall particles (4 layers) with their inner row on x = 0, x = 4, y = 0;
fluid block of int(1/dx)+1 by int(2/dx)+1 particles spanning [dx, 1 + dx] x [dx, 2 + dx] (67 x 134
= 8,978 at dx = 0.015, spacing 1/66 and 2/133 m). That is the tank and column of the MPS bench.

Defect of the example: create_particles() gives every particle the module-level h = 1.3 * 0.03
and m = 0.03^2 * 1000, i.e. the values for the default dx = 0.03 m, whatever --dx says (only the
scheme's h0 and the time step use the new dx). With --dx 0.015 the particles carry h = 0.039 m
(2.6 dx, four times the neighbours) and four times the mass. By default this runner subclasses
the example and sets h = hdx * dx and m = dx^2 * rho for the chosen dx (the case the example
means); --stock runs the example exactly as shipped.

Printed (one line): PYSPH dam_break_2d variant=<fixed|stock> dx=<m> fluid=<n> run_s=<s>
wall_s=<s> steps=<n> front_t0.4=<m> front_t0.6=<m>, with run_s = PySPH's own "Run took" (the
solver loop, as the MPS bench's wall_s) and wall_s = the whole application (setup, which compiles
or loads the generated Cython code, included). A front line per output file follows.
"""

import argparse
import glob
import os
import re
import sys
import time

from pysph.examples import dam_break_2d as db
from pysph.solver.utils import load


class DamBreak2DFixedDx(db.DamBreak2D):
    """The example with h and m of the particles set for the chosen dx."""

    def create_particles(self):
        arrays = super().create_particles()
        for pa in arrays:
            pa.h[:] = self.hdx * self.dx
            pa.m[:] = self.dx * self.dx * db.ro
        return arrays


def fronts(out_dir, fname):
    """(t, x_max of the fluid, solver step count) of every output file, in time order."""
    rows = []
    for path in glob.glob(os.path.join(out_dir, fname + "_*.hdf5")) + \
            glob.glob(os.path.join(out_dir, fname + "_*.npz")):
        data = load(path)
        sd = data["solver_data"]
        x = data["arrays"]["fluid"].get("x")
        rows.append((float(sd["t"]), float(x.max()), int(sd["count"])))
    rows.sort()
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--stock", action="store_true",
                    help="run the example as shipped (h and m of dx = 0.03)")
    ap.add_argument("--dx", type=float, default=0.015)
    ap.add_argument("--tf", type=float, default=0.6)
    ap.add_argument("--out", default="pysph_dam_break_2d_output")
    ap.add_argument("--pfreq", type=int, default=1000,
                    help="PySPH output every N steps (the example also dumps at 0.4 and 0.6 s)")
    args, extra = ap.parse_known_args()

    fname = "dam_break_2d"
    argv = ["--dx", str(args.dx), "--tf", str(args.tf), "--no-openmp", "-d", args.out,
            "--pfreq", str(args.pfreq), "-q", "--fname", fname] + extra
    for old in glob.glob(os.path.join(args.out, fname + "_*.*")):
        os.remove(old)
    cls = db.DamBreak2D if args.stock else DamBreak2DFixedDx
    app = cls(fname=fname)
    t0 = time.perf_counter()
    app.run(argv)
    wall = time.perf_counter() - t0

    run_s = float("nan")
    log = os.path.join(args.out, fname + ".log")
    if os.path.exists(log):
        with open(log) as f:
            for line in f:
                m = re.search(r"Run took:\s*([0-9.eE+-]+)", line)
                if m:
                    run_s = float(m.group(1))

    rows = fronts(args.out, fname)

    def front_at(t):
        best = [r for r in rows if abs(r[0] - t) < 1e-6]
        return best[0][1] if best else float("nan")

    steps = rows[-1][2] if rows else -1
    nfluid = app.particles[0].get_number_of_particles() if app.particles else -1
    print("PYSPH dam_break_2d variant=%s dx=%g fluid=%d run_s=%.3f wall_s=%.3f steps=%d "
          "front_t0.4=%.4f front_t0.6=%.4f options=%s"
          % ("stock" if args.stock else "fixed", args.dx, nfluid, run_s, wall, steps,
             front_at(0.4), front_at(0.6), " ".join(extra) if extra else "-"))
    for t, x, n in rows:
        print("PYSPH dam_break_2d front t=%.4f x=%.4f step=%d" % (t, x, n))
    sys.stdout.flush()


if __name__ == "__main__":
    main()
