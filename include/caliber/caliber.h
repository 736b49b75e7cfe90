#pragma once
/// \file
/// Everything of caliber's public API.

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
