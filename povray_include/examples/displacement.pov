// LB_Displacement: three spheres in one k-ary blend; the third sphere's own
// m = 0.5 halves its reach on a later blend (none here, so the surface is
// what m = 1 gives: m moves later blends only)
#version 3.7;
#include "libblend.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.5, 3.5, -7> look_at <0.5, 0, 0> angle 40 }
light_source { <10, 20, -15> rgb 1 }
light_source { <-12, 8, -6> rgb 0.4 }
#declare F = array[3];
#declare F[0] = LB_Sphere(<0, 0, 0>, 1);
#declare F[1] = LB_Sphere(<1.4, 0, 0>, 0.8);
#declare F[2] = LB_Sphere(<0.6, 1.1, 0>, 0.7);
#declare Blob = LB_Displacement(LB_UNION, F, LB_Same(F, 0.4), LB_Same(F, 2), array[3] {1, 1, 0.5})
isosurface { function { Blob(x, y, z) } contained_by { box { <-1.5, -1.5, -1.5>, <2.5, 2.2, 1.5> } }
  max_gradient 3.2 pigment { rgb <0.85, 0.65, 0.4> } }
