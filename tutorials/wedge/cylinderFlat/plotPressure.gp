# Dimensionless pressure P(X) of the thesis wedge (T-38, T-39; thesis Figure 7).
# Run from the case folder after reynoldsRef -dimensionless:  gnuplot plotPressure.gp
# (with the MPS wall pressure when ./Allrun -full has written it)
# p.dat columns: 1 x, 2 p, 3 h, 4 X, 5 P, 6 H.
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 900,600 enhanced font ",11"
} else {
    set terminal png size 900,600
}
set output "pressure.png"
set title "Rigid wedge: cylinder R = 0.04 m over a plane at U_1 = 1.2 m/s, h_0 = 40 {/Symbol m}m"
set xlabel "X = x / sqrt(R h_0)"
set ylabel "P = h_0^{3/2} p / ({/Symbol r n} U_1 sqrt(R))"
set xrange [-6:2]
set yrange [0:*]
set grid
set key top left
# Martin's exit (T-37): X = 0.475 sqrt(2)
set arrow from 0.475*sqrt(2), graph 0 to 0.475*sqrt(2), graph 1 nohead dashtype 2 lc rgb "gray40"
set label "Martin exit (T-37) " at 0.475*sqrt(2), graph 0.70 right tc rgb "gray40"
# MPS: x and p of the wallPressure function object made dimensionless with the scales of
# reynoldsRef (R = 0.04 m, h0 = 40 um, rho nu = 0.19125 Pa s, U1 = 1.2 m/s)
sx = 1 / sqrt(0.04 * 4.0e-5)
sp = (4.0e-5)**1.5 / (850 * 2.25e-4 * 1.2 * sqrt(0.04))
# the table of the latest start time: a restarted run continues the average there
# (Allrun passes it with -e "mps = '...'")
if (!exists("mps")) mps = "postProcessing/wallPressure/0/p.dat"
# Reynolds from the inlet meniscus the MPS pool reached (Allrun -full: probe film, then
# reynoldsRef -inlet), the reference the run is judged against
men = "postProcessing/reynoldsRef/meniscus.dat"
if (system("test -s " . mps . " && echo 1 || echo 0") + 0) {
    if (system("test -s " . men . " && echo 1 || echo 0") + 0) {
        plot "postProcessing/reynoldsRef/0/p.dat" using 4:5 with lines lw 2 lc rgb "black" \
             title "Reynolds equation, inlet of reynoldsRefDict", \
             men using 4:5 with lines lw 2 dt 2 lc rgb "blue" \
             title "Reynolds equation, inlet at the MPS meniscus (24-30 ms)", \
             mps using ($1 * sx):($2 * sp) with points pt 7 ps 0.5 lc rgb "red" \
             title "MPS (lubFoam), cylinder wall, mean over 24-30 ms"
    } else {
        plot "postProcessing/reynoldsRef/0/p.dat" using 4:5 with lines lw 2 lc rgb "black" \
             title "Reynolds equation (reynoldsRef)", \
             mps using ($1 * sx):($2 * sp) with points pt 7 ps 0.5 lc rgb "red" \
             title "MPS (lubFoam), cylinder wall, mean over 24-30 ms"
    }
} else {
    plot "postProcessing/reynoldsRef/0/p.dat" using 4:5 with lines lw 2 lc rgb "black" \
         title "Reynolds equation (reynoldsRef)"
}
