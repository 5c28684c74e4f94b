// LB_CleanUnion: the exact union surface of two soft spheres, C1 away from
// the intersection curve (the local-blending paper's clean union)
#version 3.7;
#include "libblend.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.5, 3.5, -7> look_at <0.5, 0, 0> angle 40 }
light_source { <10, 20, -15> rgb 1 }
light_source { <-12, 8, -6> rgb 0.4 }
#declare S1 = LB_Sphere(<0, 0, 0>, 1)
#declare S2 = LB_Sphere(<1.3, 0, 0>, 0.8)
#declare G1 = function(x, y, z) { LB_Wyvill(S1(x, y, z) + 1) }
#declare G2 = function(x, y, z) { LB_Wyvill(S2(x, y, z) + 1) }
#declare Clean = LB_CleanUnion(G1, G2, 0, 0)
isosurface { function { 0.5 - Clean(x, y, z) } contained_by { box { <-2, -2, -2>, <3, 2, 2> } }
  max_gradient 1.6 pigment { rgb <0.7, 0.7, 0.9> } }
