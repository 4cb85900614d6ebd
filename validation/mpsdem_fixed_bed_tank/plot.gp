# Plots of mpsdem_fixed_bed; run by validation/tiers.sh inside build/validation/mpsdem_fixed_bed.
set datafile separator ','
set terminal pngcairo size 1200,500 font ",11"
set grid
set output 'pressure_drop.png'
set multiplot layout 1,2
set title 'dynamic pressure drop per packing length'
set xlabel 't [s]'
set ylabel 'dP_dyn / L [Pa/m]'
plot 'pressure.csv' using 1:6 with lines title 'MPS-DEM', 15347 with lines dt 2 lw 2 title 'Ergun (eps 1 - pi/6)'
set title 'porosity relative to the bed bottom (bed: 0 to 0.064 m)'
set xlabel 'z - z_bed [m]'
set ylabel 'eps'
plot 'porosity_eq31.csv' using 1:2 with lines lw 2 title 'Eq. 31, cross-section mean', \
     'porosity.csv' using 1:2 with points pt 7 title 'FLUID particles, all', \
     'porosity.csv' using 1:3 with points pt 6 title 'FLUID particles, core'
unset multiplot
