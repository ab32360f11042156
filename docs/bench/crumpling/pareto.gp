# Written by `crumple bench` (docs/BENCH.md): ms per frame against error, each
# model's configurations and its Pareto front; zero errors drawn at 1e-09.
set terminal pngcairo size 1400,840 font ',10'
set output '/work/main/docs/bench/crumpling/pareto.png'
D = '/work/main/docs/bench/crumpling/pareto.dat'
set termoption noenhanced
set logscale xy
set grid
set key outside right top
set ylabel 'ms per frame'
set multiplot layout 2,2
set title 'crumple: c_mean (mean over frames)'
set xlabel 'c_mean (mean over frames) (%)'
plot D index 0 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 1 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 2 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 3 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
set title 'crumple: angle defect, total (mean over frames)'
set xlabel 'angle defect, total (mean over frames) (rad)'
plot D index 4 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 5 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 6 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 7 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
set title 'crumple-ball: c_mean (mean over frames)'
set xlabel 'c_mean (mean over frames) (%)'
plot D index 8 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 9 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 10 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 11 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
set title 'crumple-ball: angle defect, total (mean over frames)'
set xlabel 'angle defect, total (mean over frames) (rad)'
plot D index 12 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 13 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 14 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 15 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
unset multiplot
