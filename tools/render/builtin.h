// SPDX-License-Identifier: MIT
// Built-in scenes for `cbrdf render --builtin NAME`, exported as a scene file plus its assets.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "cbrdf/status.h"
#include "render/scene.h"

namespace cbrdf::render {

struct BuiltinScene {
  std::string name;
  std::string file;  // the scene file's name inside the export directory
  std::string description;
};

std::vector<BuiltinScene> builtin_scenes();

// Writes the scene and the assets it needs (.cbrdf materials fitted from built-in samples, a Draco
// mesh, a lat-long EXR) into dir; returns the scene file's path.
Expected<std::filesystem::path> export_builtin(const std::string& name,
                                               const std::filesystem::path& dir);

// Figure 4's layout (six unit spheres in a row, orthographic camera, one directional light; the
// "figure4" scene's geometry and light) with every sphere in material 0, at `scale` times its
// 1320x240 pixels (at least 1x1): the scene the report times one material's renders with.
Scene figure4_one_material(const MaterialDesc& material, double scale);

}  // namespace cbrdf::render
