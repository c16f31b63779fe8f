// hapticgrasp: the command-line front end of the HapticGrasp core.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>

#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/sample_parts.hpp"
#include "penetration_ladder.hpp"

namespace {

using namespace hg;
using namespace hg::geometry;

void logLine(const std::string& text) { std::cerr << text << std::endl; }

int benchPenetration(const cli::LadderOptions& options, bool json) {
  logLine("penetration ladder on " + options.part);
  const cli::LadderResult result = cli::runPenetrationLadder(options, logLine);
  if (json) std::cout << cli::toJson(result).dump(2) << std::endl;
  else cli::printLadder(result, std::cout);
  return 0;
}

int partInfo(const std::string& name) {
  const SamplePart sample = findPart(name);
  const PartModelPtr part = PartModel::fromFile(sample.file, sample.unit);
  const MassProperties m = part->massProperties(sample.mass);
  const Aabb b = part->bounds();
  std::printf("part %s (%s)\n", sample.name.c_str(), sample.file.c_str());
  std::printf("  faces %d, edges %d, vertices %d, primitive: %s\n", part->faces().Extent(), part->edges().Extent(),
              part->vertices().Extent(), toString(part->primitive().kind));
  std::printf("  bounds [m]: %.6g %.6g %.6g .. %.6g %.6g %.6g\n", b.min.x(), b.min.y(), b.min.z(), b.max.x(),
              b.max.y(), b.max.z());
  std::printf("  volume %.6g m^3, mass %.6g kg, centre of gravity [m] %.6g %.6g %.6g\n", m.volume_m3, m.mass_kg,
              m.centre_m.x(), m.centre_m.y(), m.centre_m.z());
  std::printf("  inertia about the centre [kg m^2]:\n");
  for (int r = 0; r < 3; ++r)
    std::printf("    %12.6g %12.6g %12.6g\n", m.inertia_kgm2(r, 0), m.inertia_kgm2(r, 1), m.inertia_kgm2(r, 2));
  for (const std::string& w : part->warnings()) std::printf("  note: %s\n", w.c_str());
  return 0;
}

// Until the grasp demo lands: the ladder on the paper's cylinder and the machined block,
// with fewer queries.
int demo() {
  for (const char* name : {"cylinder", "block"}) {
    cli::LadderOptions o;
    o.part = name;
    o.randomQueries = 500;
    o.coherentTicks = 4000;
    o.referenceChecks = 200;
    benchPenetration(o, false);
    std::cout << std::endl;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"HapticGrasp: feel and handle the parts of a CAD model with a haptic arm"};
  app.require_subcommand(1);

  app.add_subcommand("demo", "Run the demonstration (for now: the penetration ladder on the sample parts)");

  CLI::App* bench = app.add_subcommand("bench", "Measure speed against accuracy");
  bench->require_subcommand(1);
  cli::LadderOptions ladder;
  bool json = false;
  CLI::App* penetration = bench->add_subcommand("penetration", "The speed/accuracy ladder of the penetration back ends");
  penetration->add_option("--part", ladder.part, "Sample part (cylinder, block, loft, plate) or a .brep/.step file (mm)")
      ->capture_default_str();
  penetration->add_option("--queries", ladder.randomQueries, "Random points in the shell")->capture_default_str()->check(CLI::PositiveNumber);
  penetration->add_option("--ticks", ladder.coherentTicks, "Ticks of the coherent path")->capture_default_str()->check(CLI::PositiveNumber);
  penetration->add_option("--reference-checks", ladder.referenceChecks, "Path ticks checked against the reference")
      ->capture_default_str()->check(CLI::PositiveNumber);
  penetration->add_option("--seed", ladder.seed, "Random seed")->capture_default_str();
  penetration->add_flag("--json", json, "Print JSON");

  CLI::App* parts = app.add_subcommand("parts", "Inspect parts");
  parts->require_subcommand(1);
  std::string partName;
  CLI::App* info = parts->add_subcommand("info", "Topology, bounds, mass properties of a part");
  info->add_option("part", partName, "Sample part name or .brep/.step file (mm)")->required();

  CLI11_PARSE(app, argc, argv);
  try {
    if (app.got_subcommand("demo")) return demo();
    if (penetration->parsed()) return benchPenetration(ladder, json);
    if (info->parsed()) return partInfo(partName);
  } catch (const GeometryError& e) {
    std::cerr << "hapticgrasp: " << e.what() << std::endl;
    return 2;
  }
  return 0;
}
