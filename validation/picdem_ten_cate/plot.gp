# Plots of picdem_ten_cate; run by validation/tiers.sh inside build/validation/picdem_ten_cate.
set datafile separator ','
set terminal pngcairo size 1200,500 font ",11"
set grid
set key bottom left
set output 'ten_cate_E1.png'
set multiplot layout 1,2
set title 'ten Cate et al. (2002) E1: sphere velocity'
set xlabel 't [s]'
set ylabel 'w [m/s]'
plot 'sphere.csv' using 1:3 with lines lw 2 title 'fsdem PIC-DEM', \
     '../../../validation/data/ten_cate2002_E1_Re1.5_velocity.csv' using 1:2 with points pt 7 title 'experiment'
set title 'gap between the sphere and the floor'
set ylabel 'gap / D'
set key top right
plot 'sphere.csv' using 1:($2/0.015) with lines lw 2 title 'fsdem PIC-DEM', \
     '../../../validation/data/ten_cate2002_E1_Re1.5_gap.csv' using 1:2 with points pt 7 title 'experiment'
unset multiplot
