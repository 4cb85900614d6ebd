# Plots of the Ritter/Stoker dam breaks; run by validation/tiers.sh inside build/validation/swe_dambreak.
set datafile separator ','
set terminal pngcairo size 1200,800 font ",11"
set grid
set key top right
set xlabel 'x [m]'
do for [c in "A_ritter_dry B_stoker_wet C_swashes_ritter D_swashes_stoker"] {
    set output sprintf('profile_%s.png', c)
    set multiplot layout 2,1 title c
    set ylabel 'h [m]'
    plot sprintf('profile_%s.csv', c) using 1:4 with lines lw 3 lc rgb '#999999' title 'exact', \
         '' using 1:2 with lines lw 1.5 lc rgb '#0055cc' title 'fsdem'
    set ylabel 'u [m/s]'
    plot sprintf('profile_%s.csv', c) using 1:5 with lines lw 3 lc rgb '#999999' title 'exact', \
         '' using 1:3 with lines lw 1.5 lc rgb '#0055cc' title 'fsdem'
    unset multiplot
}
