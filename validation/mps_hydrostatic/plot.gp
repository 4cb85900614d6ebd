# Plots of mps_hydrostatic; run by validation/tiers.sh inside build/validation/mps_hydrostatic.
set datafile separator ','
set terminal pngcairo size 1200,500 font ",11"
set grid
rgh = 1000 * 9.81 * 0.2

set output 'bottom_pressure.png'
set multiplot layout 1,2
set title '2D: pressure at the bottom centre / (rho g h)'
set xlabel 't [s]'
set ylabel 'p / (rho g h)'
set yrange [0.8:1.2]
plot 'pressure.csv' using 1:($2/rgh) with lines title 'gamma 0.01', \
     'pressure_gamma0.csv' using 1:($2/rgh) with lines title 'gamma 0', \
     'pressure_r0_half.csv' using 1:($2/rgh) with lines title 'gamma 0.01, r0/2', \
     1.02 with lines dt 2 lc rgb 'red' title '+-2%', 0.98 with lines dt 2 lc rgb 'red' notitle
set title '3D'
plot 'pressure_3d.csv' using 1:($2/rgh) with lines title 'gamma 0.01', \
     'pressure_3d_gamma0.csv' using 1:($2/rgh) with lines title 'gamma 0', \
     1.02 with lines dt 2 lc rgb 'red' title '+-2%', 0.98 with lines dt 2 lc rgb 'red' notitle
unset multiplot

set output 'pressure_profile.png'
set yrange [*:*]
set multiplot layout 1,2
set title '2D: centre line at t = 0.25 s'
set xlabel 'pressure [Pa]'
set ylabel 'y [m]'
plot 'profile.csv' using 2:1 with points pt 7 title 'gamma 0.01', 'profile_gamma0.csv' using 2:1 with points pt 6 title 'gamma 0', \
     'profile.csv' using 3:1 with lines lw 2 title 'rho g (h - y)'
set title '3D'
set ylabel 'z [m]'
plot 'profile_3d.csv' using 2:1 with points pt 7 title 'gamma 0.01', 'profile_3d_gamma0.csv' using 2:1 with points pt 6 title 'gamma 0', \
     'profile_3d.csv' using 3:1 with lines lw 2 title 'rho g (h - z)'
unset multiplot

set output 'max_speed.png'
set title 'largest fluid particle speed'
set xlabel 't [s]'
set ylabel 'speed [m/s]'
set logscale y
plot 'pressure.csv' using 1:5 with lines title '2D gamma 0.01', 'pressure_gamma0.csv' using 1:5 with lines title '2D gamma 0', \
     'pressure_r0_half.csv' using 1:5 with lines title '2D r0/2', 'pressure_3d.csv' using 1:5 with lines title '3D gamma 0.01', \
     'pressure_3d_gamma0.csv' using 1:5 with lines title '3D gamma 0'
