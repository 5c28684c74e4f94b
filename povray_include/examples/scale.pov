// LB_Scale: the scale method on two ray-linear ellipsoids; its blend grows
// with the level set
#version 3.7;
#include "libblend.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.5, 3.5, -7> look_at <0.5, 0, 0> angle 40 }
light_source { <10, 20, -15> rgb 1 }
light_source { <-12, 8, -6> rgb 0.4 }
#declare F = array[2];
#declare F[0] = LB_Ellipsoid(<0, 0, 0>, <1.2, 0.6, 0.6>);
#declare F[1] = LB_Ellipsoid(<0.8, 0.5, 0>, <0.5, 1, 0.5>);
#declare S = LB_Scale(LB_UNION, F, LB_Same(F, 0.3), LB_Same(F, 2))
isosurface { function { S(x, y, z) } contained_by { box { <-1.5, -1, -1>, <1.8, 2, 1> } }
  max_gradient 2.1 pigment { rgb <0.6, 0.8, 0.5> } }
