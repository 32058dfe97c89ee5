# The surge front of the MPS run against Martin & Moyce's two experiment series.
set terminal pngcairo size 800,560 font ",11"
set output "front.png"
set xlabel "T = t (2 g / a)^{1/2}"
set ylabel "Z = x_{front} / a"
set key top left
set grid
set xrange [0:3.5]
set yrange [1:4.2]
set title "Collapse of a water column (n^2 = 2): surge front"
plot "postProcessing/probe/frontZT.dat" using 1:2 with lines lw 2 title "lubFoam (MPS)", \
     "martinMoyce1952.dat" using ($3 == 1.125 ? $1 : 1/0):2 with points pt 7 title "Martin and Moyce, a = 1.125 in", \
     "martinMoyce1952.dat" using ($3 == 2.25 ? $1 : 1/0):2 with points pt 5 title "Martin and Moyce, a = 2.25 in"
