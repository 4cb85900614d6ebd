# Plots of the cylinder-layer collapse; run by validation/tiers.sh inside build/validation/dem_cylinder_collapse.
# No digitised experiment exists (seed 000 Fig. 7 is not available as data), so the two laws are
# compared with each other and the snapshots show the deposit.
set datafile separator ','
set key autotitle columnhead
set grid

set terminal pngcairo size 1200,500 font ",11"
set output 'mass_centre.png'
set multiplot layout 1,2
set xlabel 't [s]'
set xrange [0:1]
set key bottom right
set title 'mean x of the cylinder centres (Eq. 26)'
set ylabel 'x_{ave} [m]'
plot 'mass_centre.csv' using 1:2 with lines lw 2 title 'linear (seed 000 Table 1)', \
     'mass_centre_hertz.csv' using 1:2 with lines lw 2 dt 2 title 'Hertz-Mindlin (E = 70 GPa, e = 0.5)'
set key top right
set title 'mean height of the cylinder centres'
set ylabel 'z_{ave} [m]'
plot 'mass_centre.csv' using 1:3 with lines lw 2 title 'linear (seed 000 Table 1)', \
     'mass_centre_hertz.csv' using 1:3 with lines lw 2 dt 2 title 'Hertz-Mindlin (E = 70 GPa, e = 0.5)'
unset multiplot

set output 'energy.png'
set multiplot layout 1,2
set key top right
set title 'total mechanical energy (kinetic + rotational + potential + elastic)'
set ylabel 'E [J]'
plot 'energy.csv' using 1:6 with lines lw 2 title 'linear', \
     'energy_hertz.csv' using 1:6 with lines lw 2 dt 2 title 'Hertz-Mindlin'
set title 'kinetic + rotational energy'
set ylabel 'E_k [J]'
plot 'energy.csv' using 1:($2+$3) with lines lw 2 title 'linear', \
     'energy_hertz.csv' using 1:($2+$3) with lines lw 2 dt 2 title 'Hertz-Mindlin'
unset multiplot

# Snapshots of the linear-law run; the tank is 0.286 m wide, only the lower part is shown
set terminal pngcairo size 1500,440 font ",10"
set output 'snapshots.png'
unset grid
set multiplot layout 2,3
set size ratio -1
set xrange [0:0.286]
set yrange [0:0.07]
set xlabel 'x [m]'
set ylabel 'z [m]'
set style fill solid 0.6
do for [t in "0.00 0.10 0.20 0.30 0.50 1.00"] {
    set title sprintf('t = %s s   (filled: linear law, outline: Hertz-Mindlin)', t)
    plot sprintf('particles_%s.csv', t) using 2:3:11 with circles lc rgb '#4060c0' notitle, \
         sprintf('particles_hertz_%s.csv', t) using 2:3:11 with circles fs empty lc rgb '#c04040' notitle
}
unset multiplot
