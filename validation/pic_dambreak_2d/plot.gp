# Plots of pic_dambreak_2d; run by validation/tiers.sh inside build/validation/pic_dambreak_2d.
set datafile separator ','
set key autotitle columnhead
set terminal pngcairo size 1200,500 font ",11"
set grid
a = 0.05715
g = 9.81
set output 'front_and_height.png'
set multiplot layout 1,2
set title 'surge front'
set xlabel 'T = t sqrt(2g/a)'
set ylabel 'Z = x_{front} / a'
set key top left
plot [0:5.5] 'front.csv' using ($1*sqrt(2*g/a)):($2/a) with lines lw 2 title 'fsdem a/40', \
     'front_shifted.csv' using ($1*sqrt(2*g/a)):($2/a) with lines lw 2 dt 4 title 'fsdem a/40, best-fit delay dT', \
     'front_n20.csv' using ($1*sqrt(2*g/a)):($2/a) with lines dt 2 title 'fsdem a/20', \
     'front_n10.csv' using ($1*sqrt(2*g/a)):($2/a) with lines dt 3 title 'fsdem a/10', \
     'ref_front.csv' using ($1*sqrt(2*g/a)):($2/a) with points pt 7 ps 1.2 lc rgb 'black' title 'Martin and Moyce 1952 (checked)', \
     'ref_front_ko.csv' using ($1*sqrt(2*g/a)):($2/a) with points pt 6 ps 1.4 lc rgb '#cc0000' title 'Koshizuka and Oka 1996'
set title 'residual column height'
set xlabel 'tau = t sqrt(g/a)'
set ylabel 'eta = h / (2a)'
set key top right
plot [0:8] 'front.csv' using ($1*sqrt(g/a)):($3/(2*a)) with lines lw 2 title 'fsdem a/40', \
     'front_n20.csv' using ($1*sqrt(g/a)):($3/(2*a)) with lines dt 2 title 'fsdem a/20', \
     'ref_height.csv' using ($1*sqrt(g/a)):($2/(2*a)) with points pt 7 ps 1.2 title 'Martin and Moyce 1952'
unset multiplot
