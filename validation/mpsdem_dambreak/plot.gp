# Plots of mpsdem_dambreak; run by validation/report.sh inside build/validation/mpsdem_dambreak.
# Each run wrote fronts_<model>_<r0>.csv (t,water_front,sediment_front,water_q,sediment_q); runs that
# were not made (the default set leaves some out, see README.md) are skipped.
set datafile separator ','
set terminal pngcairo size 1400,550 font ",11"
set grid
set key top left
set xlabel 't [s]'
exists(f) = system('test -s '.f.' && echo 1 || echo 0') + 0
runs = 'B_0.0030 B_0.0027 B_0.0020 A_0.0030 A_0.0027 A_0.0020'
clear = 'W_0.0030 W_0.0027 W_0.0020'
set output 'fronts.png'
set multiplot layout 1,2
set title 'Leading front of the water'
set ylabel 'x_{front} [m]'
plot [0:][0.04:0.21] for [r in runs] (exists('fronts_'.r.'.csv') ? 'fronts_'.r.'.csv' : '/dev/null') \
        using 1:2 with lines lw 2 title r, \
     for [r in clear] (exists('fronts_'.r.'.csv') ? 'fronts_'.r.'.csv' : '/dev/null') \
        using 1:2 with lines dt 2 lw 2 title r.' (clear water)', \
     0.2 with lines lc rgb 'black' dt 3 title 'far wall'
set title 'Leading front of the sediment'
set ylabel 'x_{front} [m]'
plot [0:][0.04:0.21] for [r in runs] (exists('fronts_'.r.'.csv') ? 'fronts_'.r.'.csv' : '/dev/null') \
        using 1:3 with lines lw 2 title r
unset multiplot
