# Plots of the Chung & Ooi validation; run by validation/tiers.sh inside build/validation/dem_chung_ooi.
set datafile separator ','
set key autotitle columnhead
set terminal pngcairo size 1200,500 font ",11"

# Tests 1-2: force vs time, simulation against the digitised paper curves (test 1: glass, test 2: Al alloy)
set output 'test1_2_force_time.png'
set key below
set multiplot layout 1,2
set title 'Test 1: two spheres, 20 m/s (Hertz, e = 1)'
set xlabel 'time since first contact [us]'
set ylabel 'normal force [kN]'
set grid
plot 'test1.csv' using ($1*1e6):($2/1e3) with lines lw 2 title 'fsdem glass', \
     'test1.csv' using ($1*1e6):($4/1e3) with lines lw 2 dt 2 title 'fsdem limestone', \
     'ref_test1_force_time.csv' using ($1*1e6):($2/1e3) with points pt 6 ps 1.2 title 'paper, glass (digitised)'
set title 'Test 2: sphere on a rigid plane, 0.2 m/s'
plot 'test2.csv' using ($1*1e6):($2/1e3) with lines lw 2 title 'fsdem Al alloy', \
     'test2.csv' using ($1*1e6):($4/1e3) with lines lw 2 dt 2 title 'fsdem Mg alloy', \
     'ref_test2_force_time.csv' using ($1*1e6):($2/1e3) with points pt 6 ps 1.2 title 'paper, Al alloy (digitised)'
unset multiplot

# Tests 1-2: force vs overlap (loading branch of the paper curves)
set output 'test1_2_force_overlap.png'
set multiplot layout 1,2
set title 'Test 1: force vs overlap'
set xlabel 'overlap [um]'
set ylabel 'normal force [kN]'
plot 'test1.csv' using ($3*1e6):($2/1e3) with lines lw 2 title 'fsdem glass', \
     'ref_test1_force_overlap.csv' using ($1*1e6):($2/1e3) with points pt 6 ps 1.2 title 'paper, glass (digitised)'
set title 'Test 2: force vs overlap'
plot 'test2.csv' using ($3*1e6):($2/1e3) with lines lw 2 title 'fsdem Al alloy', \
     'ref_test2_force_overlap.csv' using ($1*1e6):($2/1e3) with points pt 6 ps 1.2 title 'paper, Al alloy (digitised)'
unset multiplot

# Test 3: rebound/impact speed ratio against the input restitution
set key inside
set terminal pngcairo size 700,600 font ",11"
set output 'test3_restitution.png'
set title 'Test 3: normal impact on a rigid plane, 3.9 m/s'
set xlabel 'input restitution e'
set ylabel 'rebound speed / impact speed'
set key top left
plot x with lines lc rgb 'gray' title 'ratio = e', \
     'test3.csv' using 1:2 with points pt 7 ps 1.5 title 'fsdem Al oxide', \
     'test3.csv' using 1:3 with points pt 6 ps 2.0 title 'fsdem cast iron'

# Test 4: oblique impacts, Al oxide; spin and angle in the reference's sign convention
set terminal pngcairo size 1500,480 font ",11"
set output 'test4_oblique.png'
set multiplot layout 1,3
set xlabel 'incident angle from the normal [deg]'
set xrange [0:90]
set key bottom right
set title 'tangential restitution V_t''/V_t'
set ylabel 'V_t after / V_t before'
plot 'test4.csv' using 1:2 with lines lw 2 title 'fsdem', \
     'ref_test4.csv' using 3:(($1==1 && $2==1) ? $4 : 1/0) with points pt 6 ps 1.3 title 'paper DEM, Al oxide', \
     'ref_test4.csv' using 3:(($1==1 && $2==3) ? $4 : 1/0) with points pt 5 ps 0.9 title 'Kharaz experiment'
set key top right
set title 'angular velocity after impact'
set ylabel 'omega [rad/s]'
plot 'test4.csv' using 1:3 with lines lw 2 title 'fsdem', \
     'ref_test4.csv' using 3:(($1==2 && $2==1) ? $4 : 1/0) with points pt 6 ps 1.3 title 'paper DEM, Al oxide', \
     'ref_test4.csv' using 3:(($1==2 && $2==3) ? $4 : 1/0) with points pt 5 ps 0.9 title 'Kharaz experiment'
set key top left
set title 'rebound angle of the contact point'
set ylabel 'atan((V_t + omega R)/V_n) [deg]'
plot 'test4.csv' using 1:4 with lines lw 2 title 'fsdem', \
     'ref_test4.csv' using 3:(($1==3 && $2==1) ? $4 : 1/0) with points pt 6 ps 1.3 title 'paper DEM, Al oxide', \
     'ref_test4.csv' using 3:(($1==3 && $2==3) ? $4 : 1/0) with points pt 5 ps 0.9 title 'Kharaz experiment'
unset multiplot
