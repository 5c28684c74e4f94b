// A local union in a hand-written scene: the field comes from
// local_union_field.inc, baked by
//   blendtool pov local_union.json --include-only -o local_union_field.inc
// (the intersection curve is found by libblend when the include is made; the
// include holds it as data). Everything else here is ordinary POV-Ray: our
// own camera, lights, floor and texture. The ball blends into the capsule
// only around the curve where they meet; each keeps its own shape elsewhere.
#version 3.7;
#include "libblend.inc"
#include "local_union_field.inc"
global_settings { assumed_gamma 1.0 }
background { rgb <0.92, 0.93, 0.95> }
camera { location <1.6, 2.4, -5.2> look_at <0.1, -0.05, 0> angle 38 }
light_source { <8, 14, -10> rgb 1 }
light_source { <-10, 6, -4> rgb 0.35 shadowless }
// the floor under the capsule (its lowest point: z = -0.75 in the scene)
plane { y, -0.75 pigment { checker rgb <0.85, 0.85, 0.82> rgb <0.7, 0.72, 0.75> scale 0.5 } }
isosurface {
  function { LB_Surface(x, y, z) } // < 0 inside, 0 on the surface
  threshold 0
  contained_by { box { LB_FieldMin, LB_FieldMax } }
  max_gradient LB_FieldMaxGradient
  accuracy LB_FieldAccuracy
  texture { pigment { rgb <0.85, 0.55, 0.3> } finish { ambient 0.1 diffuse 0.7 specular 0.4 roughness 0.02 } }
  rotate -90 * x // the scene's z is up; POV-Ray's y is
}
