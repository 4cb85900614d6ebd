# Plots of mps_still_water; run by validation/tiers.sh inside build/validation/mps_still_water.
set datafile separator ','
set terminal pngcairo size 1200,500 font ",11"
set grid
set output 'displacement.png'
set multiplot layout 1,2
set title '2D: largest particle displacement'
set xlabel 't [s]'
set ylabel 'displacement / r0'
set logscale y
plot 'still_explicit_2d.csv' using 1:2 with lines title 'explicit', \
     'still_semi_implicit_2d.csv' using 1:2 with lines title 'semi-implicit (seed 002)', \
     0.4 with lines dt 2 lc rgb 'red' title 'line at 5 s'
set title '3D: largest particle displacement'
plot 'still_explicit_3d.csv' using 1:2 with lines title 'explicit', \
     'still_semi_implicit_3d.csv' using 1:2 with lines title 'semi-implicit (seed 002)', \
     0.5 with lines dt 2 lc rgb 'red' title 'line at 1 s'
unset multiplot
