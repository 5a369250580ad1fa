// dented.pov: POV-Ray 3.7 isosurface standing in for
// bench/peers/scenes/dented.rib (scenes/shaders/dented.sl on the wave's
// square): y = -0.1 sum_{i<4} 0.5^i |2 noise(4 2^i (x, 0, z)) - 1|, with
// POV-Ray's own noise (f_noise3d), which is NOT aafarm's: the two surfaces
// differ, so for this scene the benchmark compares time and holes only
// (holes against POV-Ray's own render at 4x the gradient and accuracy
// 1e-6, see bench/peers/run.sh). Same camera, light and shading as the RIB.
// Declared on the command line by bench/peers/run.sh:
//   MG   max_gradient (no closed form for f_noise3d: run.sh measures it
//        with POV-Ray's own report of the largest gradient it found)
//   ACC  accuracy
#version 3.7;
#ifndef (MG)  #declare MG = 10; #end
#ifndef (ACC) #declare ACC = 0.001; #end
global_settings { assumed_gamma 1.0 ambient_light rgb 1 }
#include "functions.inc"
#include "peers_common.inc"

PEERS_CAMERA(25, 512 / 256)

#declare WORLD_TO_CAMERA = transform { rotate <-35, 0, 0> translate <0, 0.08, 3.5> }

PEERS_LIGHT(<-1, 2, -2>, WORLD_TO_CAMERA)

isosurface {
  function {
    y + 0.1 * (      abs(2 * f_noise3d( 4 * x, 0,  4 * z) - 1)
               + 0.5   * abs(2 * f_noise3d( 8 * x, 0,  8 * z) - 1)
               + 0.25  * abs(2 * f_noise3d(16 * x, 0, 16 * z) - 1)
               + 0.125 * abs(2 * f_noise3d(32 * x, 0, 32 * z) - 1))
  }
  contained_by { box { <-1, -0.25, -1>, <1, 0.25, 1> } }
  max_gradient MG
  accuracy ACC
  open
  PEERS_MATTE(<0.8, 0.75, 0.6>, 0.15)
  transform { WORLD_TO_CAMERA }
}
