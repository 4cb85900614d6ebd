# Plots of pic_cavity; run by validation/tiers.sh inside build/validation/pic_cavity.
set datafile separator ','
set terminal pngcairo size 1200,500 font ",11"
set grid
do for [re in "100 400 1000"] {
    set output 'centrelines_Re'.re.'.png'
    set multiplot layout 1,2 title 'lid-driven cavity, Re = '.re
    set title 'u on the vertical centre line x = 0.5'
    set xlabel 'u'
    set ylabel 'y'
    plot 'centreline_Re'.re.'.csv' using 2:1 with linespoints lw 2 title 'fsdem', \
         'centreline_Re'.re.'.csv' using 3:1 with points pt 6 ps 1.5 title 'Ghia et al. 1982'
    set title 'v on the horizontal centre line y = 0.5'
    set xlabel 'x'
    set ylabel 'v'
    plot 'centreline_Re'.re.'.csv' using 4:5 with linespoints lw 2 title 'fsdem', \
         'centreline_Re'.re.'.csv' using 4:6 with points pt 6 ps 1.5 title 'Ghia et al. 1982'
    unset multiplot
}
