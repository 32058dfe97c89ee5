# The MPS wall pressure under the descending cylinder (the mean of the time folders within
# +-20 ms of each time) against the Reynolds equation between the film's menisci at the same
# times.  Run by Allrun, or from the case folder after it:
#     gnuplot -e "filmOverL0 = 8; times = '0.1 0.15 0.2'" plotPressure.gp
if (!exists("filmOverL0")) filmOverL0 = 8
if (!exists("times")) times = "0.1 0.15 0.2"
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 1000,600 enhanced font ",11"
} else {
    set terminal png size 1000,600
}
set output "pressure.png"
set title sprintf("Cylinder R = 20 mm descending at 1 mm/s onto a 1 mm oil film, l_0 = h_0/%d", filmOverL0)
set xlabel "x [mm]"
set ylabel "p [Pa]"
set yrange [0:*]
set grid
set key outside right top
plot for [i = 1:words(times)] sprintf("postProcessing/reynoldsRef/%s/p.dat", word(times, i)) \
         using ($1*1e3):2 with lines lw 2 lc i title sprintf("Reynolds, t = %s s", word(times, i)), \
     for [i = 1:words(times)] sprintf("postProcessing/probe/%s/cylinderPressure.dat", word(times, i)) \
         using ($1*1e3):2 with points pt 7 ps 0.6 lc i title sprintf("MPS, t = %s s", word(times, i))
