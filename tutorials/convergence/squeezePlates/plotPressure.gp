# The MPS wall pressure under the plate (the mean of the time folders within +-20 us of each
# time, probe wallPressure -facing down) against the Reynolds equation at the same times, as
# it is (p = 0 at the plate's ends) and raised by the ends' offset a (Allrun says why).
# Run by Allrun, or from the case folder after it:
#     gnuplot -e "filmOverL0 = 4; times = '0.0004 0.0006 0.0008'" plotPressure.gp
if (!exists("filmOverL0")) filmOverL0 = 4
if (!exists("times")) times = "0.0004 0.0006 0.0008"
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 1100,600 enhanced font ",11"
} else {
    set terminal png size 1100,600
}
set output "pressure.png"
set title sprintf("Squeeze film: plate L = 1 mm closing at 5 mm/s from h = 40 {/Symbol m}m, l_0 = h_0/%d", filmOverL0)
set xlabel "x [mm]"
set ylabel "p [kPa]"
set xrange [-0.5:0.5]
set yrange [0:*]
set grid
set key outside right top
plot for [i = 1:words(times)] sprintf("postProcessing/reynoldsRef/%s/p.dat", word(times, i)) \
         using ($1*1e3):($2*1e-3) with lines lw 2 lc i title sprintf("Reynolds, t = %g ms", word(times, i)*1e3), \
     for [i = 1:words(times)] sprintf("postProcessing/reference/%s/p.dat", word(times, i)) \
         using ($1*1e3):($2*1e-3) with lines lw 1 dt 2 lc i title "Reynolds + the ends' offset a", \
     for [i = 1:words(times)] sprintf("postProcessing/probe/%s/platePressure.dat", word(times, i)) \
         using ($1*1e3):($2*1e-3) with points pt 7 ps 0.8 lc i title sprintf("MPS, t = %g ms", word(times, i)*1e3)
