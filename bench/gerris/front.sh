#!/bin/sh
# Prints the figures of a finished Gerris run of swe2d.gfs (run in the directory holding its output):
# cell updates per second (wall and CPU), steps, front position vs 2 sqrt(g h_L) t, volume change.
# Usage: sh front.sh WALL_SECONDS CPU_SECONDS
set -eu
wall=${1:?wall seconds}; cpu=${2:?cpu seconds}
steps=$(tail -1 swe2d_time.txt | awk '{print $2}')
awk -v steps="$steps" -v wall="$wall" -v cpu="$cpu" 'NR > 1 {
    n++; vol += $4
    if ($4 > 1e-3 && $1 > far) far = $1
    if ($4 < 0 || $4 > 1.0001) bad++
} END {
    g = 9.81; t = 0.5; travel = 2 * sqrt(g) * t; thr = travel - 3 * sqrt(g * 1e-3) * t
    front = far - 3.5; dx = 8.0 / 1024
    printf "BENCH gerris_swe2d cells=%d\n", n
    printf "BENCH gerris_swe2d steps=%d\n", steps
    printf "BENCH gerris_swe2d cell_updates_per_s=%.4g cells*steps/s\n", n * steps / wall
    printf "BENCH gerris_swe2d cell_updates_per_cpu_s=%.4g cells*steps/s\n", n * steps / cpu
    printf "BENCH gerris_swe2d front_1e-3=%.4f m (farthest cell centre with h > 1e-3 h_L, from the dam)\n", front
    printf "BENCH gerris_swe2d front_error_vs_travel=%.2f %% (of the travel %.4f m)\n", 100 * (front - travel) / travel, travel
    printf "BENCH gerris_swe2d front_error_vs_exact_1e-3_contour=%.2f %%\n", 100 * (front - thr) / travel
    printf "BENCH gerris_swe2d relative_volume_change=%.3g\n", (vol * dx * (1.0 / 128) - 4) / 4
    printf "BENCH gerris_swe2d cells_with_bad_depth=%d\n", bad
}' swe2d_end.txt
