// SPDX-License-Identifier: MIT
/// @file
/// The decoder's API in one include: what a renderer needs to open a .cbrdf file, evaluate and
/// sample it, and rebuild the MERL table. Links cbrdf::decoder (zstd and xxhash only).
#pragma once

#include "cbrdf/brdf_table.h"  // BrdfTable: the MERL-resolution table
#include "cbrdf/codec.h"       // decode_model, decode_table, inspect_container
#include "cbrdf/coords.h"      // Vec3 and the MERL grid
#include "cbrdf/merl_io.h"     // read_merl, write_merl
#include "cbrdf/model.h"       // Model, ModelEvaluator
#include "cbrdf/sampling.h"    // BrdfSampler, make_model_sampler
#include "cbrdf/status.h"      // Status, Expected
#include "cbrdf/version.h"     // CBRDF_VERSION, version_string()
