// LB_Displacement as an intersection: three slabs make a cube with blended
// edges; P = 4 makes the edges squarer than the default 2
#version 3.7;
#include "libblend.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.5, 3.5, -7> look_at <0.5, 0, 0> angle 40 }
light_source { <10, 20, -15> rgb 1 }
light_source { <-12, 8, -6> rgb 0.4 }
#declare F = array[3];
#declare F[0] = LB_Slab(<0, 0, 0>, x, 1);
#declare F[1] = LB_Slab(<0, 0, 0>, y, 1);
#declare F[2] = LB_Slab(<0, 0, 0>, z, 1);
#declare Cube = LB_Displacement(LB_INTERSECTION, F, LB_Same(F, 0.4), LB_Same(F, 4), LB_Same(F, 1))
isosurface { function { Cube(x, y, z) } contained_by { box { <-1.2, -1.2, -1.2>, <1.2, 1.2, 1.2> } }
  max_gradient 1.05 pigment { rgb <0.5, 0.7, 0.85> } }
