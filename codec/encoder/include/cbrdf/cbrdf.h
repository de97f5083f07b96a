// SPDX-License-Identifier: MIT
/// @file
/// cbrdf's C++ API in one include: the decoder (cbrdf/decoder.h) and the encoder (fitting, rate
/// control, built-in samples). Links cbrdf::encoder; a program that only reads files includes
/// cbrdf/decoder.h and links cbrdf::decoder. The C API is cbrdf/cbrdf_c.h.
#pragma once

#include "cbrdf/decoder.h"
#include "cbrdf/encoder.h"       // encode_table, EncoderSettings (FitSettings + ContainerSettings)
#include "cbrdf/fit.h"           // fit_model, FitSettings, FitReport
#include "cbrdf/rate_control.h"  // encode_to_target
#include "cbrdf/samples.h"       // make_sample: the built-in materials
