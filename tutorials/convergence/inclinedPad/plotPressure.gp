# The MPS wall pressure under the pad (mean over the second half of the run, probe
# wallPressure -facing down) against the Reynolds equation, as it is (p = 0 at both edges)
# and with the pad's ends at the pressures Allrun fits.  Run by Allrun, or from the case
# folder after it: gnuplot -e "filmOverL0 = 4; window = '0.0005-0.001 s'" plotPressure.gp
if (!exists("filmOverL0")) filmOverL0 = 4
if (!exists("window")) window = "second half of the run"
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 900,600 enhanced font ",11"
} else {
    set terminal png size 900,600
}
set output "pressure.png"
set title sprintf("Inclined pad: L = 1 mm, h_1 = 40 {/Symbol m}m, h_0 = 20 {/Symbol m}m, U_1 = 1.2 m/s, l_0 = h_0/%d", filmOverL0)
set xlabel "x [mm]"
set ylabel "p [kPa]"
set xrange [0:1]
set yrange [0:*]
set grid
set key top left
plot "postProcessing/reynoldsRef/0/p.dat" using ($1*1e3):($2*1e-3) with lines lw 2 lc rgb "black" \
         title "Reynolds (the closed form)", \
     "postProcessing/reference/p.dat" using ($1*1e3):($2*1e-3) with lines lw 1 dt 2 lc rgb "blue" \
         title "Reynolds with the ends' pressures fitted (Allrun)", \
     "postProcessing/probe/padPressure.dat" using ($1*1e3):($2*1e-3) with points pt 7 ps 0.8 \
         lc rgb "red" title "MPS, pad's lower face, mean ".window
