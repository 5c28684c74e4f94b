// LB_SoftHyper (soft convention, surface at 0.5): two Wyvill soft spheres
// in a super-ellipsoidal union; the second one's m = 2
#version 3.7;
#include "libblend.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.5, 3.5, -7> look_at <0.5, 0, 0> angle 40 }
light_source { <10, 20, -15> rgb 1 }
light_source { <-12, 8, -6> rgb 0.4 }
#declare S1 = LB_Sphere(<0, 0, 0>, 1)
#declare S2 = LB_Sphere(<1.6, 0, 0>, 0.8)
#declare G = array[2];
#declare G[0] = function(x, y, z) { LB_Wyvill(S1(x, y, z) + 1) };
#declare G[1] = function(x, y, z) { LB_Wyvill(S2(x, y, z) + 1) };
#declare U = LB_SoftHyper(LB_UNION, G, LB_Same(G, 0.5), LB_Same(G, 2), array[2] {1, 2})
isosurface { function { 0.5 - U(x, y, z) } contained_by { box { <-1.5, -1.5, -1.5>, <2.8, 1.5, 1.5> } }
  max_gradient 0.9 pigment { rgb <0.9, 0.75, 0.45> } }
