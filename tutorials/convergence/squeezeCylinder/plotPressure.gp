# The MPS wall pressure of the cylinder (the mean of the time folders within +-20 us of each
# time, probe wallPressure) against the Reynolds equation at the same times, between the
# menisci of the MPS film.
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
set title sprintf("Squeeze film: cylinder R = 5 mm closing at 5 mm/s from h_0 = 20 {/Symbol m}m, l_0 = h_0/%d", filmOverL0)
set xlabel "x [mm]"
set ylabel "p [kPa]"
set xrange [-0.7:0.7]
set yrange [0:*]
set grid
set key outside right top
plot for [i = 1:words(times)] sprintf("postProcessing/reynoldsRef/%s/p.dat", word(times, i)) \
         using ($1*1e3):($2*1e-3) with lines lw 2 lc i title sprintf("Reynolds, t = %g ms", word(times, i)*1e3), \
     for [i = 1:words(times)] sprintf("postProcessing/probe/%s/cylinderPressure.dat", word(times, i)) \
         using ($1*1e3):($2*1e-3) with points pt 7 ps 0.8 lc i title sprintf("MPS, t = %g ms", word(times, i)*1e3)
