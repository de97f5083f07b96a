// The measurements behind `cbrdf report`: encode, decode and compare each material.
#pragma once

#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/status.h"

namespace cbrdf::report {

struct Material {
  std::string name;
  std::string path;  // MERL .binary; empty for a built-in sample
  bool builtin = false;
};

struct Settings {
  int slices = 6;
  int bits = EncodeSettings{}.bits;
  int jobs = 1;
  bool progress = true;  // a progress line on stderr
};

struct Row {
  std::string material;
  double input_bytes = 0;
  double container_bytes = 0;
  double psnr_linear = 0, psnr_tonemapped = 0;  // sphere images, decoded vs input
  double rel_rmse = 0, log_rmse = 0;            // over measured bins
  double encode_seconds = 0, decode_seconds = 0;
  double eval_ns_per_sample = 0;  // ModelEvaluator::eval, random direction pairs
};

Expected<std::vector<Row>> measure_all(const std::vector<Material>& materials, const Settings& st);
std::string format_table(const std::vector<Row>& rows);
Status write_files(const std::vector<Row>& rows, const std::string& dir);

}  // namespace cbrdf::report
