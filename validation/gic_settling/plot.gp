# Plots of gic_settling; run by validation/tiers.sh inside build/validation/gic_settling.
set datafile separator ','
set terminal pngcairo size 900,500 font ",11"
set grid
set output 'settling_velocity.png'
set title 'one granule settling in still water (GIC law, Eq. 5b): velocity down'
set xlabel 't [s]'
set ylabel 'w [m/s]'
ut = sqrt(1500 * 9.81 * 7.8e-4 / (18 * 0.44 * 1000))
plot 'settling_R8.csv' using 1:(-$3) with lines lw 2 title 'granule (dx = 8 d)', \
     'settling_R8.csv' using 1:(-$4) with lines title 'water at the granule', \
     ut with lines dt 2 lc rgb 'black' title 'u_t of the law'
