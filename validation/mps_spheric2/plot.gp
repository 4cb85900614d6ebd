# Plots of mps_spheric2; run by validation/tiers.sh inside build/validation/mps_spheric2.
set datafile separator ','
set terminal pngcairo size 1400,800 font ",11"
set grid
set output 'gauges.png'
set multiplot layout 2,2
set xlabel 't [s]'
set ylabel 'water level [m]'
set title 'gauge x = 0.496 m (behind the box; file column H3)'
plot [0:6] 'heights.csv' using 1:2 with lines lw 2 title 'MPS', 'ref_heights.csv' using 1:2 with lines title 'experiment'
set title 'gauge x = 0.992 m (file H2)'
plot [0:6] 'heights.csv' using 1:3 with lines lw 2 title 'MPS', 'ref_heights.csv' using 1:3 with lines title 'experiment'
set title 'gauge x = 1.488 m (file H1)'
plot [0:6] 'heights.csv' using 1:4 with lines lw 2 title 'MPS', 'ref_heights.csv' using 1:4 with lines title 'experiment'
set title 'gauge x = 2.638 m (in the reservoir; file H4)'
plot [0:6] 'heights.csv' using 1:5 with lines lw 2 title 'MPS', 'ref_heights.csv' using 1:5 with lines title 'experiment'
unset multiplot
set output 'pressure_P1.png'
set terminal pngcairo size 1000,500 font ",11"
set title 'pressure at P1 (front face of the box, z = 0.021 m)'
set ylabel 'p [Pa]'
plot [0:3] 'ref_pressure.csv' using 1:2 with lines title 'experiment', 'pressure.csv' using 1:2 with lines lw 2 title 'MPS'
