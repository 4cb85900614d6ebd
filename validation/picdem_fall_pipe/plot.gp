# Plots of the fall-pipe dumping (seed 000 section 3.3); run by validation/tiers.sh inside
# build/validation/picdem_fall_pipe. Column 1 of both files is 0 for the continuous pipe, 1 for the
# perforated one. No reference data exist (seed 000 Fig. 12 shows snapshots only).
set datafile separator ','
set grid
set terminal pngcairo size 1300,500 font ",11"

set output 'levels.png'
set multiplot layout 1,2
set xlabel 't [s]'
set ylabel 'water level [m]'
set key bottom left
set title 'continuous pipe: level inside (median of the pipe columns) and outside'
plot 'levels.csv' using ($1 == 0 ? $2 : 1/0):3 with lines lw 2 title 'inside', \
     'levels.csv' using ($1 == 0 ? $2 : 1/0):(($4 + $5) / 2) with lines lw 2 title 'outside (mean of x = 4 and 24 cm)'
set title 'perforated pipe'
plot 'levels.csv' using ($1 == 1 ? $2 : 1/0):3 with lines lw 2 title 'inside', \
     'levels.csv' using ($1 == 1 ? $2 : 1/0):(($4 + $5) / 2) with lines lw 2 title 'outside (mean of x = 4 and 24 cm)'
unset multiplot

set output 'cylinders.png'
set multiplot layout 1,2
set key top right
set title 'cylinders whose centre is above the pipe bottom'
set ylabel 'count'
plot 'cylinders.csv' using ($1 == 0 ? $2 : 1/0):3 with lines lw 2 title 'continuous', \
     'cylinders.csv' using ($1 == 1 ? $2 : 1/0):3 with lines lw 2 title 'perforated'
set title 'mean height of the cylinder centres'
set ylabel 'y_{ave} [m]'
plot 'cylinders.csv' using ($1 == 0 ? $2 : 1/0):6 with lines lw 2 title 'continuous', \
     'cylinders.csv' using ($1 == 1 ? $2 : 1/0):6 with lines lw 2 title 'perforated'
unset multiplot
