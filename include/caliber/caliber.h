#pragma once
/// \file
/// Everything of caliber's public API: one pair (mesh, model, pose, query), frames and the parallel
/// engine, scene files and the world that makes frames from them, and the version.

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/export.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "caliber/scene.h"
#include "caliber/version.h"
#include "caliber/world.h"
