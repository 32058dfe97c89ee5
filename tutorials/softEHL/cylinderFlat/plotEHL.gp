# Soft EHL: dimensionless pressure P(X) and film H(X) of the MPS run against the Reynolds-EHL
# reference (T-54..T-58: X = x/b, P = p/p_H, H = h R/b^2), and the load history of the
# elastic wall.  Allrun runs it as  gnuplot -e "b = ...; pH = ..." plotEHL.gp  (ehl.png),
# with the Hertz half-width b and pressure p_H of log.reynoldsRef.
#
# Files (Allrun writes them; the MPS ones are left out when absent or without rows):
#   postProcessing/reynoldsRef/0/p.dat          # x p h X P H
#   postProcessing/wallPressure/0/p.dat         # x[m] p[Pa] n  (lubFoam function object, time mean)
#   postProcessing/probe/wallShape.dat          # x y v h X H    (probe wallShape)
#   postProcessing/probe/film.dat               # x h surface bottom contact n X H (probe film)
#   postProcessing/elasticWall/0/elasticWall.dat  # t h0 centre load loadTarget ... (lubFoam)
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 900,1100 enhanced font ",11"
} else {
    set terminal png size 900,1100
}
set output "ehl.png"
# without -e: the scales of this case (log.reynoldsRef: b, p_H)
if (!exists("b")) b = 0.00113809
if (!exists("pH")) pH = 559373
ref = "postProcessing/reynoldsRef/0/p.dat"
# the table of the latest start time: a restarted run continues the average there
# (Allrun passes it with -e "pw = '...'")
if (!exists("pw")) pw = "postProcessing/wallPressure/0/p.dat"
ws = "postProcessing/probe/wallShape.dat"
fm = "postProcessing/probe/film.dat"
if (!exists("ew")) ew = "postProcessing/elasticWall/0/elasticWall.dat"
set multiplot layout 3,1
set grid
set key bottom center

set title "Pressure on the elastic cylinder"
set xlabel "X = x / b"
set ylabel "P = p / p_H"
set yrange [0:*]
if (system("grep -qsv '^#' " . pw . " && echo 1 || echo 0") + 0) {
    plot ref using 4:5 with lines lw 2 lc rgb "black" title "Reynolds-EHL (reynoldsRef)", \
         pw using ($1 / b):($2 / pH) with points pt 7 ps 0.5 lc rgb "red" \
         title "MPS wall pressure (lubFoam, time mean)"
} else {
    plot ref using 4:5 with lines lw 2 lc rgb "black" title "Reynolds-EHL (reynoldsRef)"
}

set title "Film thickness"
set ylabel "H = h R / b^2"
set yrange [0:*]
set key top left
if (system("grep -qsv '^#' " . ws . " && echo 1 || echo 0") + 0) {
    plot ref using 4:6 with lines lw 2 lc rgb "black" title "Reynolds-EHL", \
         ws using 5:6 with lines lw 1.5 lc rgb "red" title "MPS: elastic wall above the plane (probe wallShape)", \
         fm using 7:8 with points pt 6 ps 0.5 lc rgb "blue" title "MPS: oil film (probe film)"
} else {
    plot ref using 4:6 with lines lw 2 lc rgb "black" title "Reynolds-EHL"
}

set title "Load balance (T-51..T-53)"
set xlabel "t [ms]"
set ylabel "load [N/m]"
set yrange [0:*]
set key bottom right
if (system("grep -qsv '^#' " . ew . " && echo 1 || echo 0") + 0) {
    plot ew using ($1 * 1e3):5 with lines lw 2 lc rgb "black" title "load W(t)", \
         ew using ($1 * 1e3):4 with lines lw 1.5 lc rgb "red" title "integral of the mean wall pressure", \
         ew using ($1 * 1e3):8 with dots lc rgb "gray60" title "integral of the wall pressure"
} else {
    unset key
    set label 1 "no MPS run yet" at graph 0.5, 0.5 center
    plot [0:1][0:1] 2 notitle
}
unset multiplot
