// Everything in haze::core: include this, or the headers under haze/core/ you need.
#pragma once

#include <haze/core/camera.h>
#include <haze/core/directions.h>
#include <haze/core/error.h>
#include <haze/core/image.h>
#include <haze/core/light.h>
#include <haze/core/math.h>
#include <haze/core/medium.h>
#include <haze/core/method.h>
#include <haze/core/phase.h>
#include <haze/core/phase_matrix.h>
#include <haze/core/progress.h>
#include <haze/core/rng.h>
#include <haze/core/scene.h>
#include <haze/core/solution.h>
#include <haze/core/stopwatch.h>
#include <haze/core/surface.h>
