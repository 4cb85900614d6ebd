# Plots of gic_volume; run by validation/tiers.sh inside build/validation/gic_volume.
set datafile separator ','
set terminal pngcairo size 1200,500 font ",11"
set grid
set output 'volume.png'
set multiplot layout 1,2
set title 'water volume the grid sees, over its start (sand ball into water, 2D)'
set xlabel 't [s]'
set ylabel 'fluid volume / initial'
v1 = system("awk -F, 'NR == 2 { print $2 }' volume_idp1.csv") + 0
v0 = system("awk -F, 'NR == 2 { print $2 }' volume_idp0.csv") + 0
plot 'volume_idp1.csv' using 1:($2 / v1) with lines lw 2 title 'density projection (Eq. 12b-13)', \
     'volume_idp0.csv' using 1:($2 / v0) with lines title 'without', \
     1.005 with lines dt 2 lc rgb 'black' title '+-0.5 %', 0.995 with lines dt 2 lc rgb 'black' notitle
set title 'water level at x = 0.1 m'
set ylabel 'level [m]'
plot 'volume_idp1.csv' using 1:5 with lines lw 2 title 'density projection', \
     'volume_idp0.csv' using 1:5 with lines title 'without'
unset multiplot
