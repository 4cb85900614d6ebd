# Plots of mpsdem_sedimentation (seed 002 Figs. 3-5); run by validation/tiers.sh inside
# build/validation/mpsdem_sedimentation, where checks.txt (the program's output) gives the analytic values.
set datafile separator ','
set terminal pngcairo size 1000,600 font ",11"
set grid
set key top right
set xlabel 't [s]'
num(pat) = real(system("sed -n 's|.*model B: analytic.*" . pat . " = \\([0-9.eE+-]*\\) .*|\\1|p' checks.txt | head -1"))
pref = num('rho g H')
buoy = num('sum V rho_f g')
wsub = 1.5 * buoy  # (rho_s - rho_f) / rho_f = 1.5
hlev = num('H = (V_f + V_s)/A')

set output 'kinetic_energy.png'
set title 'Kinetic energy of the spheres (seed 002 Fig. 3)'
set ylabel 'E_k [J]'
set logscale y
plot 'series_A.csv' using 1:2 with lines lw 2 title 'Model A', \
     'series_B.csv' using 1:2 with lines lw 2 title 'Model B'
unset logscale y

set output 'bottom_pressure.png'
set title 'Pressure at the bottom centre (seed 002 Fig. 4)'
set ylabel 'p [Pa]'
set yrange [0:2*pref]
plot 'series_A.csv' using 1:3 with lines title 'Model A', \
     'series_B.csv' using 1:3 with lines title 'Model B', \
     pref with lines dt 2 lw 2 lc rgb 'black' title 'rho_f g H', \
     1.02*pref with lines dt 3 lc rgb 'red' title '+-2%', 0.98*pref with lines dt 3 lc rgb 'red' notitle
set yrange [*:*]

set output 'fluid_forces.png'
set title 'Fluid forces on the sediment (seed 002 Fig. 5)'
set ylabel 'force [N]'
plot 'series_A.csv' using 1:4 with lines title '|sum F^d| A', \
     'series_B.csv' using 1:4 with lines title '|sum F^d| B', \
     'series_A.csv' using 1:7 with lines title '|sum pressure part| A', \
     'series_B.csv' using 1:7 with lines title '|sum pressure part| B', \
     buoy with lines dt 2 lw 2 lc rgb 'black' title 'sum V rho_f g', \
     0.01*wsub with lines dt 3 lc rgb 'red' title '1% of submerged weight'

set output 'level_bed.png'
set title 'Water level at the centre and top of the bed'
set ylabel 'z [m]'
plot 'series_A.csv' using 1:8 with lines title 'level A', 'series_B.csv' using 1:8 with lines title 'level B', \
     hlev with lines dt 2 lc rgb 'black' title 'H = (V_f + V_s)/A', \
     'series_A.csv' using 1:9 with lines title 'bed top A', 'series_B.csv' using 1:9 with lines title 'bed top B'
