# The MPS wall pressure (time-averaged, function object wallPressure) against the Reynolds
# equation from the MPS inlet meniscus.  Run by Allrun, or from the case folder after it:
#     gnuplot -e "filmOverL0 = 4; window = '0.0006-0.0012 s'" plotPressure.gp
if (!exists("filmOverL0")) filmOverL0 = 4
if (!exists("window")) window = "the window"
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 900,600 enhanced font ",11"
} else {
    set terminal png size 900,600
}
set output "pressure.png"
set title sprintf("Slender wedge: R = 160 mm, U_1 = 1.2 m/s, h_0 = 60 {/Symbol m}m, l_0 = h_0/%d", filmOverL0)
set xlabel "x [mm]"
set ylabel "p [kPa]"
set xrange [-1.9:1.1]
set yrange [0:*]
set grid
set key top right
plot "postProcessing/reynoldsRef/0/p.dat" using ($1*1e3):($2*1e-3) with lines lw 2 lc rgb "black" \
         title "Reynolds, inlet at the MPS meniscus", \
     "postProcessing/wallPressure/0/p.dat" using ($1*1e3):($2*1e-3) with points pt 7 ps 0.6 \
         lc rgb "red" title "MPS, mean ".window
