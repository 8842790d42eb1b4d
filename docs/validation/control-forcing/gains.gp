# gnuplot gains.gp  ->  gains.svg: Re_T and <n_a> of the a = 4 stand-in against control forcing's integral gain
set terminal svg size 900,380 font "sans,12"
set output "gains.svg"
# du: the well depth du/U_inf; seed 1; dashed: direct forcing (the paper's markers, 2 sweeps), seed 1
set multiplot layout 1,2
set xrange [0.5:3.5]
set xtics 1
set xlabel "integral gain G (proportional 0)"
set key top left font ",10"
set ylabel "Re_T"
set yrange [1.6:2.8]
plot "gains.dat" u 1:2:3 w yerrorlines pt 7 t "control forcing, du 0", \
     "" u 1:6:7 w yerrorlines pt 5 t "control forcing, du 0.02", \
     1.91 w l dt 2 lc 1 t "direct forcing, du 0", 2.13 w l dt 2 lc 2 t "direct forcing, du 0.02"
set ylabel "<n_a>"
set yrange [0:90]
set key top left font ",10"
plot "gains.dat" u 1:4:5 w yerrorlines pt 7 t "control forcing, du 0", \
     "" u 1:8:9 w yerrorlines pt 5 t "control forcing, du 0.02", \
     3.7 w l dt 2 lc 1 t "direct forcing, du 0", 41.0 w l dt 2 lc 2 t "direct forcing, du 0.02"
unset multiplot
