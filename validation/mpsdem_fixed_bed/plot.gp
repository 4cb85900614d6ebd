set datafile separator ','
set terminal pngcairo size 900,600
set output 'history.png'
set title 'mpsdem\_fixed\_bed: superficial velocity over the Ergun target'
set xlabel 't (s)'
set ylabel 'U_s / U_{Ergun}'
set logscale x
set yrange [0:1.2]
set key off
plot 'history.csv' every ::1 using 5:7 with points pt 7 ps 0.3
