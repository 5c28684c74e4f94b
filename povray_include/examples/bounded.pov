// LB_Bounded: two spheres blend only inside their bounding spheres (twice
// their size): the blend stops where a bounding solid ends
#version 3.7;
#include "libblend.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.5, 3.5, -7> look_at <0.5, 0, 0> angle 40 }
light_source { <10, 20, -15> rgb 1 }
light_source { <-12, 8, -6> rgb 0.4 }
#declare F = array[2];
#declare F[0] = LB_Sphere(<0, 0, 0>, 1);
#declare F[1] = LB_Sphere(<1.6, 0, 0>, 0.7);
#declare C = array[2];
#declare C[0] = LB_Sphere(<0, 0, 0>, 1.5);
#declare C[1] = LB_Sphere(<1.6, 0, 0>, 1.05);
#declare B = LB_Bounded(LB_UNION, F, C, LB_Same(F, 2))
isosurface { function { B(x, y, z) } contained_by { box { <-1.5, -1.5, -1.5>, <2.5, 1.5, 1.5> } }
  max_gradient 1.6 pigment { rgb <0.75, 0.6, 0.85> } }
