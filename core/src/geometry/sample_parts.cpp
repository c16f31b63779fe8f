#include "hapticgrasp/geometry/sample_parts.hpp"

#include <nlohmann/json.hpp>

#include "hapticgrasp/install_layout.hpp"

#include <fstream>

namespace hg::geometry {

std::filesystem::path resourcesDir() { return hg::resourcesDir(); }

std::vector<SamplePart> sampleParts() {
  const std::filesystem::path dir = resourcesDir() / "parts";
  std::ifstream in(dir / "parts.json");
  if (!in) throw GeometryError("no sample part catalogue at " + (dir / "parts.json").string());
  std::vector<SamplePart> parts;
  try {
    for (const auto& entry : nlohmann::json::parse(in)) {
      SamplePart p;
      p.name = entry.at("name").get<std::string>();
      p.file = dir / entry.at("file").get<std::string>();
      p.unit = parseLengthUnit(entry.value("unit", "mm"));
      p.mass = entry.contains("mass_kg") ? MassSpec::mass(entry["mass_kg"].get<double>())
                                         : MassSpec::density(entry.value("density_kg_m3", 1000.0));
      parts.push_back(p);
    }
  } catch (const nlohmann::json::exception& e) {
    throw GeometryError("broken sample part catalogue " + (dir / "parts.json").string() + ": " + e.what());
  }
  return parts;
}

SamplePart findPart(const std::string& nameOrFile) {
  if (std::filesystem::path(nameOrFile).has_extension()) {
    SamplePart p;
    p.name = std::filesystem::path(nameOrFile).stem().string();
    p.file = nameOrFile;
    p.mass = MassSpec::density(1000.0);
    return p;
  }
  std::string names;
  for (const SamplePart& p : sampleParts()) {
    if (p.name == nameOrFile) return p;
    names += (names.empty() ? "" : ", ") + p.name;
  }
  throw GeometryError("no sample part '" + nameOrFile + "' (" + names + ", or a .brep/.step file)");
}

}  // namespace hg::geometry
