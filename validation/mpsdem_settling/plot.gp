# Plots of mpsdem_settling; run by validation/tiers.sh inside build/validation/mpsdem_settling.
set datafile separator ','
set terminal pngcairo size 1200,500 font ",11"
set grid
set output 'settling_velocity.png'
set multiplot layout 1,2
set title 'mean settling speed of the particles in the measuring box (down positive)'
set xlabel 't [s]'
set ylabel 'v [m/s]'
# the default run writes phi 0.1 only (--phi=all for the others)
plot 'settling_ergun_wen_yu_phi0.1.csv' using 1:2 with lines title 'phi 0.1'
set title 'mean vertical fluid velocity: box (solid) and within r_e of the walls (dashed)'
set ylabel 'u [m/s]'
plot 'settling_ergun_wen_yu_phi0.1.csv' using 1:3 with lines lc 1 title 'phi 0.1', \
     'settling_ergun_wen_yu_phi0.1.csv' using 1:8 with lines lc 1 dt 2 notitle
unset multiplot
