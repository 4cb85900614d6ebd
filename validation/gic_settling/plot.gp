# Plots of gic_settling; run by validation/tiers.sh inside build/validation/gic_settling.
set datafile separator ','
set terminal pngcairo size 1300,500 font ",11"
set grid
set output 'settling_velocity.png'
set title 'one granule settling in still water (GIC law, Eq. 5b): velocity down'
set xlabel 't [s]'
set ylabel 'w [m/s]'
ut = sqrt(1500 * 9.81 * 7.8e-4 / (18 * 0.44 * 1000))
set multiplot layout 1,2
plot 'settling_R8_vm1.csv' using 1:(-$3) with lines lw 2 title 'granule, virtual mass (dx = 8 d)', \
     'settling_R8_vm0.csv' using 1:(-$3) with lines title 'granule, no virtual mass', \
     'settling_R8_vm1.csv' using 1:(-$4) with lines title 'water at the granule', \
     ut with lines dt 2 lc rgb 'black' title 'u_t of the law'
set title 'the start: w = u_t tanh(t / tau), tau = u_t / a0'
set xrange [0:0.03]
a0 = 1500 * 9.81 / 2500
a1 = 1500 * 9.81 / 3000
plot 'settling_R8_vm1.csv' using 1:(-$3) with points pt 7 ps 0.5 title 'virtual mass', \
     'settling_R8_vm0.csv' using 1:(-$3) with points pt 6 ps 0.5 title 'no virtual mass', \
     ut * tanh(x * a1 / ut) with lines lc rgb 'black' title 'analytic, C_a = 1/2', \
     ut * tanh(x * a0 / ut) with lines dt 2 lc rgb 'black' title 'analytic, no added mass'
unset multiplot
