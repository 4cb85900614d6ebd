# Plots of the wet cylinder dam break; run by validation/tiers.sh inside
# build/validation/picdem_cylinder_dambreak. No digitised experiment exists (seed 000 Fig. 8-10 are
# not available as data), so beta = 0.5 and beta = 1 and the layer counts are compared with each other.
set datafile separator ','
set grid

set terminal pngcairo size 1300,500 font ",11"
set output 'cylinders.png'
set multiplot layout 1,2
set xlabel 't [s]'
set xrange [0:0.6]
set key top left
set title 'mean x of the cylinder centres (solid: beta = 0.5, dashed: beta = 1)'
set ylabel 'x_{ave} [m]'
plot for [L in "6 8 10 12"] sprintf('cylinders_%s_b0.5.csv', L) using 1:2 with lines lw 2 lc (int(L)/2) title sprintf('%s layers', L), \
     for [L in "6 8 10 12"] sprintf('cylinders_%s_b1.0.csv', L) using 1:2 with lines lw 2 dt 2 lc (int(L)/2) notitle
set key bottom right
set title 'water front on the floor (solid: beta = 0.5, dashed: beta = 1)'
set ylabel 'x_{front} [m]'
plot for [L in "6 8 10 12"] sprintf('cylinders_%s_b0.5.csv', L) using 1:5 with lines lw 2 lc (int(L)/2) title sprintf('%s layers', L), \
     for [L in "6 8 10 12"] sprintf('cylinders_%s_b1.0.csv', L) using 1:5 with lines lw 2 dt 2 lc (int(L)/2) notitle
unset multiplot

# arrival times from the INFO lines "arrival L<n> <beta 0.5> <beta 1>" of checks.txt
set terminal pngcairo size 700,500 font ",11"
set output 'arrival.png'
set datafile separator whitespace
set xrange [5:13]
set yrange [0:*]
set xlabel 'layers'
set ylabel 'arrival time at the right wall [s]'
set title 'first cylinder at the right wall (seed 000 Fig. 10)'
set key bottom right
plot "< awk '$3 == \"arrival\" { sub(/^L/, \"\", $4); print $4, $5, $6 }' checks.txt" using 1:($2 >= 0 ? $2 : 1/0) with linespoints lw 2 pt 7 title 'beta = 0.5', \
     '' using 1:($3 >= 0 ? $3 : 1/0) with linespoints lw 2 dt 2 pt 5 title 'beta = 1 (no gap treatment)'
set datafile separator ','

# Snapshots: water particles (dots) and cylinders, beta = 0.5 left, beta = 1 right
unset grid
set style fill solid 0.8
set size ratio -1
set xrange [0:0.286]
set yrange [0:0.15]
set xlabel 'x [m]'
set ylabel 'z [m]'
do for [L in "6 12"] {
    set terminal pngcairo size 1400,1500 font ",10"
    set output sprintf('snapshots_%s.png', L)
    set multiplot layout 5,2
    do for [t in "0.00 0.10 0.20 0.30 0.40"] {
        do for [b in "0.5 1.0"] {
            set title sprintf('%s layers, beta = %s, t = %s s', L, b, t)
            plot sprintf('water_%s_b%s_%s.csv', L, b, t) every ::1 using 1:2 with dots lc rgb '#3080d0' notitle, \
                 sprintf('cylinders_%s_b%s_%s.csv', L, b, t) every ::1 using 2:3:11 with circles lc rgb '#a04020' notitle
        }
    }
    unset multiplot
}
