# Written by `crumple bench` (docs/BENCH.md): ms per frame against error, each
# model's configurations and its Pareto front; zero errors drawn at 1e-09.
set terminal pngcairo size 1400,1680 font ',10'
set output '/work/main/docs/bench/pareto.png'
D = '/work/main/docs/bench/pareto.dat'
set termoption noenhanced
set logscale xy
set grid
set key outside right top
set ylabel 'ms per frame'
set multiplot layout 4,2
set title 'cylinder-fold: c_mean (mean over frames)'
set xlabel 'c_mean (mean over frames) (%)'
plot D index 0 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 1 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 2 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 3 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
set title 'cylinder-fold: angle defect, total (mean over frames)'
set xlabel 'angle defect, total (mean over frames) (rad)'
plot D index 4 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 5 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 6 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 7 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
set title 'first-singularity: c_mean (mean over frames)'
set xlabel 'c_mean (mean over frames) (%)'
plot D index 8 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 9 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 10 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 11 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
set title 'first-singularity: angle defect, total (mean over frames)'
set xlabel 'angle defect, total (mean over frames) (rad)'
plot D index 12 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 13 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 14 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 15 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
set title 'moebius: c_mean (mean over frames)'
set xlabel 'c_mean (mean over frames) (%)'
plot D index 16 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 17 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 18 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 19 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
set title 'moebius: angle defect, total (mean over frames)'
set xlabel 'angle defect, total (mean over frames) (rad)'
plot D index 20 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 21 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 22 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 23 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
set title 'unload: c_mean (mean over frames)'
set xlabel 'c_mean (mean over frames) (%)'
plot D index 24 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 25 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 26 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 27 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
set title 'unload: angle defect, total (mean over frames)'
set xlabel 'angle defect, total (mean over frames) (rad)'
plot D index 28 with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid', D index 29 with lines lw 2 lc rgb '#d62728' title 'hybrid front', D index 30 with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic', D index 31 with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'
unset multiplot
