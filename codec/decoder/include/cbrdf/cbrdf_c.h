/* SPDX-License-Identifier: MIT */
/** @file
 * The whole cbrdf C API: the decoder part (cbrdf/cbrdf_decode.h: open, describe, evaluate and
 * sample .cbrdf files; libcbrdf_decoder) and the encoder part (cbrdf/cbrdf_encode.h: fit and write
 * them; libcbrdf_encoder only). A program that links only the decoder library should include
 * cbrdf/cbrdf_decode.h instead. Defining CBRDF_EXPERIMENTAL_API before this include also declares
 * the experimental calls (not covered by the ABI promise; see cbrdf/cbrdf_decode.h). */
#ifndef CBRDF_CBRDF_C_H_
#define CBRDF_CBRDF_C_H_

#include "cbrdf/cbrdf_decode.h"
#include "cbrdf/cbrdf_encode.h"

#endif /* CBRDF_CBRDF_C_H_ */
