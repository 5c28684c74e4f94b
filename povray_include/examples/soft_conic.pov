// LB_SoftConic: the binary conic soft union of two Blinn blobs
#version 3.7;
#include "libblend.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.5, 3.5, -7> look_at <0.5, 0, 0> angle 40 }
light_source { <10, 20, -15> rgb 1 }
light_source { <-12, 8, -6> rgb 0.4 }
#declare S1 = LB_Sphere(<0, 0, 0>, 1)
#declare S2 = LB_Sphere(<1.5, 0, 0>, 0.8)
#declare G1 = function(x, y, z) { LB_Blinn(S1(x, y, z) + 1) }
#declare G2 = function(x, y, z) { LB_Blinn(S2(x, y, z) + 1) }
#declare U = LB_SoftConic(LB_UNION, G1, G2, array[2] {0.5, 0.5}, 0, array[2] {1, 1})
isosurface { function { 0.5 - U(x, y, z) } contained_by { box { <-1.6, -1.6, -1.6>, <2.6, 1.6, 1.6> } }
  max_gradient 1.0 pigment { rgb <0.5, 0.75, 0.75> } }
