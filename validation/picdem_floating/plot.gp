# Plots of picdem_floating; run by validation/tiers.sh inside build/validation/picdem_floating.
set datafile separator ','
set terminal pngcairo size 1200,500 font ",11"
set grid
set output 'floating_height.png'
set multiplot layout 1,2
set title 'floating bodies (rho_s = 500): centre height'
set xlabel 't [s]'
set ylabel 'centre height [m]'
plot 'floating_2d.csv' using 1:2 with lines title '2D disc', 'floating_3d.csv' using 1:2 with lines title '3D sphere'
set title 'neutrally buoyant bodies: centre height'
plot 'neutral_2d.csv' using 1:2 with lines title '2D disc', 'neutral_3d.csv' using 1:2 with lines title '3D sphere'
unset multiplot
