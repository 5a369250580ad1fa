// nail.pov: POV-Ray 3.7 isosurface of bench/peers/scenes/nail.rib (the
// nail of scenes/shaders/nail.sl, Heidrich & Seidel 1998 Figure 5): the
// disk y = 0 of radius 0.5, displaced along +y inside the shaft r < 0.05
// (r = |(x, z)|) by 1 - 4 r (Km 1, tip 0.2), a discontinuous step at
// r = 0.05. Same camera, lights and matte shading as the RIB, in RenderMan
// camera space.
// Declared on the command line by bench/peers/run.sh:
//   MG   max_gradient: the step has no bound; the continuous parts have
//        |grad| <= sqrt(1 + 4^2) = 4.12 (the shaft's cone)
//   ACC  accuracy
#version 3.7;
#ifndef (MG)  #declare MG = 4.12; #end
#ifndef (ACC) #declare ACC = 0.001; #end
global_settings { assumed_gamma 1.0 ambient_light rgb 1 }
#include "peers_common.inc"

// RenderMan: Projection "perspective" "fov" [18] on 256x512: the fov spans
// the shorter (horizontal) side
PEERS_CAMERA(18, 256 / 512)

#declare WORLD_TO_CAMERA = transform { rotate <-20, 0, 0> translate <0, -0.7, 4> }

PEERS_LIGHT(<-2, 3, -3>, WORLD_TO_CAMERA)

isosurface {
  // inside the disk: y - H(r); outside it (r > 0.5): no surface. The
  // container reaches 1e-4 below the disk, so the cylinder r = 0.5 that
  // the max() makes there is far thinner than a pixel.
  function {
    max(y - select(sqrt(x * x + z * z) - 0.05, 1 - 4 * sqrt(x * x + z * z), 0),
        sqrt(x * x + z * z) - 0.5)
  }
  contained_by { box { <-0.5, -0.0001, -0.5>, <0.5, 1.01, 0.5> } }
  max_gradient MG
  accuracy ACC
  open
  PEERS_MATTE(<0.7, 0.7, 0.75>, 0.1)
  transform { WORLD_TO_CAMERA }
}
