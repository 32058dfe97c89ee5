# MPS wall pressure (time-averaged, function object wallPressure) against the Reynolds
# equation.  Run from the case folder after Allrun:  gnuplot plotPressure.gp
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 900,600 enhanced font ",11"
} else {
    set terminal png size 900,600
}
set output "pressure.png"
set title "Reduced wedge, two levels (OPT): l_0 = h_0/8 in [-1.0, 0.6] mm, 2 l_0 elsewhere"
set xlabel "x [mm]"
set ylabel "p [kPa]"
set xrange [-1.5:1]
set yrange [0:*]
set grid
set key top right
plot "postProcessing/reynoldsRef/0/p.dat" using ($1*1e3):($2*1e-3) with lines lw 2 lc rgb "black" \
         title "Reynolds, inlet at MPS meniscus", \
     "postProcessing/wallPressure/0/p.dat" using ($1*1e3):($2*1e-3) with points pt 7 ps 0.6 \
         lc rgb "red" title "MPS, mean 0.6-1.2 ms"
