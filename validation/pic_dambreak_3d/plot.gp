# Plots of pic_dambreak_3d; run by validation/tiers.sh inside build/validation/pic_dambreak_3d.
set datafile separator ','
set key autotitle columnhead
set terminal pngcairo size 800,600 font ",11"
set grid
a = 0.05715
g = 9.81
set output 'front_3d.png'
set title 'surge front, 3D (a/20) against the experiments and the 2D run'
set xlabel 'T = t sqrt(2g/a)'
set ylabel 'Z = x_{front} / a'
set key top left
plot 'front_2d.csv' using ($1*sqrt(2*g/a)):($2/a) with lines lw 3 title '2D', \
     'front_thin.csv' using ($1*sqrt(2*g/a)):($2/a) with lines lw 2 dt 2 title '3D thin (a/4)', \
     'front_wide.csv' using ($1*sqrt(2*g/a)):($2/a) with lines lw 2 dt 3 title '3D wide (a)', \
     'front_wide_shifted.csv' using ($1*sqrt(2*g/a)):($2/a) with lines lw 2 dt 4 title '3D wide, best-fit delay dT', \
     'ref_front.csv' using ($1*sqrt(2*g/a)):($2/a) with points pt 7 ps 1.2 lc rgb 'black' title 'Martin and Moyce 1952 (checked)', \
     'ref_front_ko.csv' using ($1*sqrt(2*g/a)):($2/a) with points pt 6 ps 1.4 lc rgb '#cc0000' title 'Koshizuka and Oka 1996'
