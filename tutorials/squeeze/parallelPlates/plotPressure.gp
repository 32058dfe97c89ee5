# The MPS wall pressure under the plate (the mean of the time folders within +-20 ms of each
# time, probe wallPressure -facing down) against the Reynolds equation at the same times
# (left), and the film-centre pressure history against reynoldsRef -series (right).
# Run by Allrun, or from the case folder after it:
#     gnuplot -e "filmOverL0 = 8; times = '0.1 0.2 0.3'" plotPressure.gp
if (!exists("filmOverL0")) filmOverL0 = 8
if (!exists("times")) times = "0.1 0.2 0.3"
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 1400,550 enhanced font ",11"
} else {
    set terminal png size 1400,550
}
set output "pressure.png"
set multiplot layout 1,2 title sprintf("Squeeze film: plate L = 20 mm closing at 1 mm/s from h = 1 mm, l_0 = h_0/%d", filmOverL0)
set xlabel "x [mm]"
set ylabel "p [Pa]"
set xrange [-10:10]
set yrange [0:*]
set grid
set key top left
plot for [i = 1:words(times)] sprintf("postProcessing/reynoldsRef/%s/p.dat", word(times, i)) \
         using ($1*1e3):2 with lines lw 2 lc i title sprintf("Reynolds, t = %s s", word(times, i)), \
     for [i = 1:words(times)] sprintf("postProcessing/closedForm/%s/p.dat", word(times, i)) \
         using ($1*1e3):3 with lines lw 1 dt 2 lc i notitle, \
     for [i = 1:words(times)] sprintf("postProcessing/probe/%s/platePressure.dat", word(times, i)) \
         using ($1*1e3):2 with points pt 7 ps 0.6 lc i title sprintf("MPS, t = %s s", word(times, i))
set xlabel "t [s]"
set ylabel "p_c [Pa]"
set xrange [0:*]
plot "postProcessing/reynoldsRef/0/pc.dat" using 1:2 with lines lw 2 lc "blue" title "Reynolds (film centre)", \
     "postProcessing/probe/0/pCentre.dat" using 1:2 with points pt 7 ps 0.7 lc "red" title "MPS"
unset multiplot
