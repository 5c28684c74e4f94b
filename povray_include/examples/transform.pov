// LB_Transform and R-functions: a rounded box (LP metric) stretched, turned
// and moved the way POV-Ray moves objects, in an R-function union with a sphere
#version 3.7;
#include "libblend.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.5, 3.5, -7> look_at <0.5, 0, 0> angle 40 }
light_source { <10, 20, -15> rgb 1 }
light_source { <-12, 8, -6> rgb 0.4 }
#declare Box = LB_Transform(LB_LP(<0, 0, 0>, <1, 1, 1>, 6), <1, 0.5, 0.8>, <0, 30, 20>, <0.8, 0, 0>)
#declare Ball = LB_Sphere(<-0.6, 0.4, 0>, 0.7)
#declare Both = LB_RUnion(Box, Ball)
isosurface { function { Both(x, y, z) } contained_by { box { <-2, -1.5, -1.5>, <2.5, 1.5, 1.5> } }
  max_gradient 2.2 pigment { rgb <0.6, 0.6, 0.6> } }
