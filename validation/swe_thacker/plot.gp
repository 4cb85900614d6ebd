# Plots of Thacker's planar bowl; run by validation/tiers.sh inside build/validation/swe_thacker.
set datafile separator ','
set terminal pngcairo size 1200,500 font ",11"
set grid
set output 'thacker_profiles.png'
set multiplot layout 1,2
set xlabel 'x [m] (section y = 2 m)'
set ylabel 'z [m]'
set key top center
set title 'after one period'
plot 'profile_T1.csv' using 1:6 with lines lw 2 lc rgb '#8b5a2b' title 'bed', \
     '' using 1:5 with lines lw 3 lc rgb '#999999' title 'exact surface', \
     '' using 1:($2 > 0 ? $4 : 1/0) with linespoints pt 7 ps 0.4 lc rgb '#0055cc' title 'fsdem surface'
set title 'after three periods'
plot 'profile_T3.csv' using 1:6 with lines lw 2 lc rgb '#8b5a2b' title 'bed', \
     '' using 1:5 with lines lw 3 lc rgb '#999999' title 'exact surface', \
     '' using 1:($2 > 0 ? $4 : 1/0) with linespoints pt 7 ps 0.4 lc rgb '#0055cc' title 'fsdem surface'
unset multiplot
set output 'thacker_time.png'
set multiplot layout 1,2
set xlabel 't [s]'
set title 'centre of mass'
set ylabel 'x, y [m]'
set key bottom right
plot 'thacker.csv' using 1:7 with lines lw 3 lc rgb '#999999' title 'x exact', \
     '' using 1:5 with lines lw 1.5 lc rgb '#0055cc' title 'x fsdem', \
     '' using 1:8 with lines lw 3 lc rgb '#bbbbbb' title 'y exact', \
     '' using 1:6 with lines lw 1.5 dt 2 lc rgb '#cc3300' title 'y fsdem'
set title 'L1 error of h / volume'
set ylabel 'relative L1'
unset key
plot 'thacker.csv' using 1:3 with lines lw 2 lc rgb '#0055cc'
unset multiplot
