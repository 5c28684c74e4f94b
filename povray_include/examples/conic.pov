// LB_Conic: two cylinders joined by a binary conic blend; Shape < 0 gives a
// flatter fillet than the quarter ellipse (Shape = 0)
#version 3.7;
#include "libblend.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.5, 3.5, -7> look_at <0.5, 0, 0> angle 40 }
light_source { <10, 20, -15> rgb 1 }
light_source { <-12, 8, -6> rgb 0.4 }
#declare C1 = LB_Cylinder(<0, 0, 0>, x, 0.5)
#declare C2 = LB_Cylinder(<0, 0, 0>, y, 0.5)
#declare Joint = LB_Conic(LB_UNION, C1, C2, array[2] {0.6, 0.6}, -0.2, array[2] {1, 1})
isosurface { function { Joint(x, y, z) } contained_by { box { <-2, -2, -1>, <2, 2, 1> } }
  max_gradient 2.2 pigment { rgb <0.8, 0.5, 0.5> } }
