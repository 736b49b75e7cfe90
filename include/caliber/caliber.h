#pragma once
/// \file
/// caliber's API for a program that runs queries and steps: meshes and models, poses, the query
/// between two models, frames, the broad phase and the parallel engine, errors and the version. Opt-in beside it:
/// caliber/profile.h (how the engine cut and scheduled a step, and the load-balance simulation),
/// caliber/scene.h and caliber/world.h (scene files and the world that makes frames from them),
/// caliber/procedural.h (small generated meshes). docs/api.md lists every public type.

#include "caliber/batch.h"
#include "caliber/broad_phase.h"
#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/executor.h"
#include "caliber/export.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/query.h"
#include "caliber/sweep.h"
#include "caliber/version.h"
