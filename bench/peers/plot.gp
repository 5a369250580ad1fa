# bench/peers/plot.gp: docs/peers.png, drawn by bench/peers/run.sh from its
# Embree sweep: CPU seconds (whole process, median) and data memory
# (vertices + BVH) of the Embree tessellation against the grid size N, one
# line per scene, with aafarm's figures for the same scene as flat lines
# (CPU of aafarm-worker, 1 thread; its box cache peak).
#   gnuplot -e "datafile='sweep.dat'; outfile='peers.png'; scenes='wave nail'" plot.gp
# sweep.dat columns: scene N cpu phases dataMiB differ aafarm_cpu aafarm_dataMiB
set terminal pngcairo size 1100,420 font ",10" noenhanced
set output outfile
set multiplot layout 1,2 title "Embree tessellation (points) vs aafarm (flat lines), one thread"
set logscale xy 2
set xlabel "N (grid cells per side)"
set key top left
set grid
sel(s) = sprintf("< awk '$1 == \"%s\"' '%s'", s, datafile)
set ylabel "CPU seconds"
set logscale y 10
plot for [i=1:words(scenes)] sel(word(scenes, i)) using 2:3 with linespoints lc i pt 7 title "Embree ".word(scenes, i), \
     for [i=1:words(scenes)] sel(word(scenes, i)) using 2:7 with lines lc i dt 2 title "aafarm ".word(scenes, i)
set ylabel "MiB"
plot for [i=1:words(scenes)] sel(word(scenes, i)) using 2:5 with linespoints lc i pt 7 title "Embree vertices+BVH ".word(scenes, i), \
     for [i=1:words(scenes)] sel(word(scenes, i)) using 2:8 with lines lc i dt 2 title "aafarm box cache ".word(scenes, i)
unset multiplot
