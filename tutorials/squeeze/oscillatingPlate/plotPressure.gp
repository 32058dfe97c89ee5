# The film-centre pressure of the oscillating plate: MPS (probe points -history) against the
# Reynolds equation at every time folder, with p >= 0 (a film without tension, the MPS
# fluid's) and with tension (fullSommerfeld, the closed form 5.5 (c)).  Run by Allrun, or from
# the case folder after it:
#     gnuplot -e "filmOverL0 = 8" plotPressure.gp
if (!exists("filmOverL0")) filmOverL0 = 8
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 900,600 enhanced font ",11"
} else {
    set terminal png size 900,600
}
set output "pressure.png"
set title sprintf("Oscillating plate: L = 20 mm, h = 1 mm - 0.2 mm (1 - cos 2{/Symbol p}t), film centre, l_0 = h_0/%d", filmOverL0)
set xlabel "t [s]"
set ylabel "p_c [Pa]"
set xrange [0:1]
set grid
set key top right
set arrow from 0.5, graph 0 to 0.5, graph 1 nohead dt 3 lc "gray"
plot "postProcessing/reynoldsRef/0/pcFullSommerfeld.dat" using 1:2 with lines lw 1 dt 2 lc "black" \
         title "Reynolds with tension (5.5 (c))", \
     "postProcessing/reynoldsRef/0/pc.dat" using 1:2 with lines lw 2 lc "blue" \
         title "Reynolds, p >= 0", \
     "postProcessing/closedForm/pc.dat" using 1:($3 > 0 ? $3 : 0) with lines lw 1 lc "cyan" \
         title "+ ends' correction", \
     "postProcessing/probe/0/pCentre.dat" using 1:2 with points pt 7 ps 0.7 lc "red" \
         title "MPS"
