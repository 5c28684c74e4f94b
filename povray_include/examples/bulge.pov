// LB_Bulge: two crossing cylinders blended with bulge elimination of the
// ranges (Flags 1): the blend narrows where the surfaces are nearly tangent
#version 3.7;
#include "libblend.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.5, 3.5, -7> look_at <0.5, 0, 0> angle 40 }
light_source { <10, 20, -15> rgb 1 }
light_source { <-12, 8, -6> rgb 0.4 }
#declare C1 = LB_Cylinder(<0, 0, 0>, x, 0.5)
#declare C2 = LB_Cylinder(<0, 0, 0>, y, 0.5)
#declare W = LB_Bulge(0, LB_UNION, C1, C2, array[2] {0.4, 0.4}, array[2] {2, 2}, 0,
                      array[2] {1, 1}, 1, 0.001, 1e-5)
isosurface { function { W(x, y, z) } contained_by { box { <-2, -2, -1>, <2, 2, 1> } }
  max_gradient 2.2 pigment { rgb <0.85, 0.55, 0.35> } }
