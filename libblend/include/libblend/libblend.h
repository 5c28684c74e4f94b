/* libblend — the umbrella header: include this one. */
#ifndef LIBBLEND_H
#define LIBBLEND_H

#include "common.h"
#include "operators.h"
#include "primitives.h"
#include "scene.h"
#include "mesh.h"
#include "volume.h"
#include "pov.h"
#include "output.h"

#endif
