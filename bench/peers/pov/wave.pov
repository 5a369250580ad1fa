// wave.pov: POV-Ray 3.7 isosurface of bench/peers/scenes/wave.rib (the
// wave of scenes/shaders/wave.sl, Heidrich & Seidel 1998 Figure 1): the
// square y = 0, -1..1 in x and z, displaced along +y by
//     h(r) = 0.1 exp(-2 r) sin(8 PI r),  r = |(x, z)| / 2
// (the shader's r is measured in (s,t) = ((x+1)/2, (z+1)/2) from (0.5, 0.5)).
// Same camera, light and matte shading as the RIB; everything is placed in
// RenderMan camera space (POV-Ray's axes are left-handed like RenderMan's).
// Declared on the command line by bench/peers/run.sh:
//   MG   max_gradient (the analytic bound of |grad(y - h)| is 1.61)
//   ACC  accuracy
#version 3.7;
#ifndef (MG)  #declare MG = 1.61; #end
#ifndef (ACC) #declare ACC = 0.001; #end
global_settings { assumed_gamma 1.0 ambient_light rgb 1 }
#include "peers_common.inc"

// RenderMan: Projection "perspective" "fov" [25] on 512x256: the fov spans
// the shorter (vertical) side
PEERS_CAMERA(25, 512 / 256)

#declare WORLD_TO_CAMERA = transform { rotate <-35, 0, 0> translate <0, 0.08, 3.5> }

PEERS_LIGHT(<-1, 2, -2>, WORLD_TO_CAMERA)

isosurface {
  function {
    y - 0.1 * exp(-2 * (0.5 * sqrt(x * x + z * z)))
            * sin(8 * pi * (0.5 * sqrt(x * x + z * z)))
  }
  contained_by { box { <-1, -0.25, -1>, <1, 0.25, 1> } }
  max_gradient MG
  accuracy ACC
  open
  PEERS_MATTE(<0.8, 0.75, 0.6>, 0.15)
  transform { WORLD_TO_CAMERA }
}
