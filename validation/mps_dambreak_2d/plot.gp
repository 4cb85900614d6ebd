# Plots of mps_dambreak_2d; run by validation/tiers.sh inside build/validation/mps_dambreak_2d.
set datafile separator ','
set terminal pngcairo size 1500,500 font ",11"
set grid
a = 0.05715
L = 0.146
g = 9.81
set output 'front_and_height.png'
set multiplot layout 1,3
set title 'Martin and Moyce column: surge front'
set xlabel 'T = t sqrt(2g/a)'
set ylabel 'Z = x_{front} / a'
set key top left
plot [0:5.5][0:9] 'front.csv' using ($1*sqrt(2*g/a)):($2/a) with lines lw 2 title 'MPS a/40 (checked)', \
     'front_other.csv' using ($1*sqrt(2*g/a)):($2/a) with lines dt 3 title 'MPS a/40, the other scheme', \
     'front_shifted.csv' using ($1*sqrt(2*g/a)):($2/a) with lines dt 4 title 'MPS a/40, best-fit delay', \
     'front_n20.csv' using ($1*sqrt(2*g/a)):($2/a) with lines dt 2 title 'MPS a/20', \
     'ref_front.csv' using ($1*sqrt(2*g/a)):($2/a) with points pt 7 ps 1.2 lc rgb 'black' title 'Martin and Moyce 1952', \
     'ref_front_ko.csv' using ($1*sqrt(2*g/a)):($2/a) with points pt 6 ps 1.4 lc rgb '#cc0000' title 'Koshizuka and Oka 1996'
set title 'Martin and Moyce column: residual height'
set xlabel 'tau = t sqrt(g/a)'
set ylabel 'eta = h / (2a)'
set key top right
plot [0:8][0:1.1] 'front.csv' using ($1*sqrt(g/a)):($3/(2*a)) with lines lw 2 title 'MPS a/40', \
     'front_other.csv' using ($1*sqrt(g/a)):($3/(2*a)) with lines dt 3 title 'MPS a/40, the other scheme', \
     'front_n20.csv' using ($1*sqrt(g/a)):($3/(2*a)) with lines dt 2 title 'MPS a/20', \
     'ref_height.csv' using ($1*sqrt(g/a)):($2/(2*a)) with points pt 7 ps 1.2 title 'Martin and Moyce 1952'
set title 'Koshizuka and Oka column (L = 0.146 m, tank 4L)'
set xlabel 'T = t sqrt(2g/L)'
set ylabel 'Z = x_{front} / L'
set key top left
plot [0:4][0:4.2] 'front_ko.csv' using ($1*sqrt(2*g/L)):($2/L) with lines lw 2 title 'MPS L/40', \
     'ref_front_ko_L.csv' using ($1*sqrt(2*g/L)):($2/L) with points pt 6 ps 1.4 lc rgb '#cc0000' title 'Koshizuka and Oka 1996'
unset multiplot

set output 'number_density.png'
set terminal pngcairo size 900,500 font ",11"
set title 'mean n/n0 of the fluid particles not on the surface (a/40)'
set xlabel 't [s]'
set ylabel 'n / n0'
set key top right
stats 'density.csv' every ::1::1 using 2 nooutput
n_first = STATS_min
plot 'density.csv' using 1:2 with lines lw 2 title 'MPS a/40', n_first * 1.01 with lines dt 2 title '+-1% of the first step', \
     n_first * 0.99 with lines dt 2 notitle
