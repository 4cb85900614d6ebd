# Plots of mpsdem_dambreak; run by validation/tiers.sh inside build/validation/mpsdem_dambreak.
# Each run wrote fronts_<model>_<r0>.csv (t,water_front,sediment_front,water_q,sediment_q); runs that
# were not made (the default set leaves some out, see README.md) are skipped.
set datafile separator ','
set terminal pngcairo size 1400,550 font ",11" noenhanced
set grid
set key top left
set xlabel 't [s]'
# the runs whose files exist (the default set leaves some out)
runs = system('ls fronts_[AB]_*.csv 2>/dev/null | sed "s/fronts_//; s/.csv//" | tr "\\n" " "')
clear = system('ls fronts_W_*.csv 2>/dev/null | sed "s/fronts_//; s/.csv//" | tr "\\n" " "')
set output 'fronts.png'
set multiplot layout 1,2
set title 'Leading front of the water'
set ylabel 'front x [m]'
plot [0:][0.04:0.21] for [r in runs] 'fronts_'.r.'.csv' \
        using 1:2 with lines lw 2 title r, \
     for [r in clear] 'fronts_'.r.'.csv' \
        using 1:2 with lines dt 2 lw 2 title r.' (clear water)', \
     0.2 with lines lc rgb 'black' dt 3 title 'far wall'
set title 'Leading front of the sediment'
set ylabel 'front x [m]'
plot [0:][0.04:0.21] for [r in runs] 'fronts_'.r.'.csv' \
        using 1:3 with lines lw 2 title r
unset multiplot
