#pragma once
// The sample parts shipped in resources/parts (the first paper's cylinder, a machined
// block, a loft, a perforated plate), described by resources/parts/parts.json.
#include <filesystem>
#include <string>
#include <vector>

#include "hapticgrasp/geometry/part_model.hpp"

namespace hg::geometry {

struct SamplePart {
  std::string name;
  std::filesystem::path file;
  LengthUnit unit = LengthUnit::Millimetre;
  MassSpec mass;
};

// hg::resourcesDir() (install_layout.hpp): $HAPTICGRASP_RESOURCES, the source tree's resources/
// for a build-tree binary, the installed share folder for an installed one.
std::filesystem::path resourcesDir();
std::vector<SamplePart> sampleParts();  // throws GeometryError if parts.json is missing or broken
// A sample part by name, or any .brep/.step file (mass: density 1000 kg/m^3, unit mm).
SamplePart findPart(const std::string& nameOrFile);

}  // namespace hg::geometry
