# Plots of mpsdem_obstacle; run by validation/tiers.sh inside build/validation/mpsdem_obstacle.
set datafile separator ','
set terminal pngcairo size 1400,900 font ",11"
set grid
set key top right
set output 'obstacle_forces.png'
set multiplot layout 2,2
set xlabel 't [s]'
set ylabel '-F_x [N]'
set title 'fluid force on the obstacle (MPS pressure on its faces), against the flow'
plot for [k=0:3] sprintf('series_%d.csv', k) using 1:(-$2) with lines title sprintf('case %d', k)
set title 'sediment contact force on the obstacle (DEM wall)'
plot for [k=1:3] sprintf('series_%d.csv', k) using 1:(-$3) with lines title sprintf('case %d', k)
set ylabel 'p [Pa]'
set title 'pressure at P1 (front face, z = 0.021 m)'
plot for [k=0:3] sprintf('series_%d.csv', k) using 1:4 with lines title sprintf('case %d', k)
set ylabel 'x [m]'
set title 'fronts: water (lines), sediment (points)'
plot for [k=0:3] sprintf('series_%d.csv', k) using 1:9 with lines title sprintf('water, case %d', k), \
     for [k=1:3] sprintf('series_%d.csv', k) using 1:10 every 20 with points title sprintf('sediment, case %d', k)
unset multiplot
set output 'gauges.png'
set terminal pngcairo size 1000,500 font ",11"
set ylabel 'water level [m]'
set title 'water level at x = 0.992 m (gauge between the reservoir and the obstacle)'
plot for [k=0:3] sprintf('series_%d.csv', k) using 1:6 with lines title sprintf('case %d', k)
