// SPDX-License-Identifier: MIT
// The settings the C++ API defaulted to before EncoderSettings{} became the command's: the
// 1.0-1.2 coding with full metadata at fixed bits. Tests that pin those files' bytes, chunk
// layouts or sizes ask for them by name.
#pragma once

#include "cbrdf/container_writer.h"
#include "cbrdf/encoder.h"

namespace cbrdf::testing {

inline ContainerSettings coding_1_2() {
  ContainerSettings s;
  s.format = ContainerSettings::Format::kV12;
  s.metadata = ContainerSettings::Metadata::kFull;
  return s;
}

// coding_1_2() at ContainerSettings::bits (12 unless changed), with no bits search.
inline EncoderSettings encoder_1_2() {
  EncoderSettings st;
  st.container = coding_1_2();
  st.auto_bits.enabled = false;
  return st;
}

}  // namespace cbrdf::testing
