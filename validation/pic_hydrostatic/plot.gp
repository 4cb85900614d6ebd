# Plots of pic_hydrostatic; run by validation/tiers.sh inside build/validation/pic_hydrostatic.
set datafile separator ','
set terminal pngcairo size 1200,500 font ",11"
set grid

set output 'pressure_profile.png'
set multiplot layout 1,2
set title '2D: pressure in the middle column at t = 2 s'
set xlabel 'pressure [Pa]'
set ylabel 'y [m]'
plot 'profile_2d.csv' using 2:1 with points pt 7 title 'fsdem', 'profile_2d.csv' using 3:1 with lines lw 2 title 'rho g (h - y)'
set title '3D'
plot 'profile_3d.csv' using 2:1 with points pt 7 title 'fsdem', 'profile_3d.csv' using 3:1 with lines lw 2 title 'rho g (h - y)'
unset multiplot

set output 'spurious_velocity.png'
set title 'largest particle speed'
set xlabel 't [s]'
set ylabel 'speed [m/s]'
set logscale y
plot 'hydrostatic_2d.csv' using 1:2 with lines lw 2 title '2D', 'hydrostatic_3d.csv' using 1:2 with lines lw 2 title '3D', \
     'hydrostatic_2d_jitter.csv' using 1:2 with lines dt 2 title '2D jittered seeds', \
     'hydrostatic_3d_jitter.csv' using 1:2 with lines dt 2 title '3D jittered seeds', 1e-3 with lines lc rgb 'red' title 'tolerance'
