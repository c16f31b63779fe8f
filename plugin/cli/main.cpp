// hapticgrasp: the command-line front end of the HapticGrasp core.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <regex>
#include <stdexcept>
#include <utility>

#include "hapticgrasp/install_layout.hpp"
#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/isolated_load.hpp"
#include "hapticgrasp/geometry/occt_faults.hpp"
#include "hapticgrasp/geometry/sample_parts.hpp"
#include "hapticgrasp/grasp/grasp_cylinder_experiment.hpp"
#include "hapticgrasp/grasp/shake_experiment.hpp"
#include "device_commands.hpp"
#include "doctor.hpp"
#include "session_commands.hpp"
#include "peg_in_hole.hpp"
#include "penetration_ladder.hpp"

namespace {

using namespace hg;
using namespace hg::geometry;

void logLine(const std::string& text) { std::cerr << text << std::endl; }

// An error as one line: OpenCASCADE's messages run over lines ("EXCEPTION in
// BinTools_CurveSet::ReadCurve(..)\n0x55e1... : Standard_ConstructionError: ..."), and the
// object's address means nothing to the user.
std::string oneLine(const std::string& message) {
  static const std::regex address("0x[0-9a-fA-F]+ : ");
  std::string text = std::regex_replace(message, address, "");
  std::string out;
  for (char c : text) {
    if (c == '\n' || c == '\r') {
      if (!out.empty() && out.back() != ' ') out += "; ";
    } else {
      out += c;
    }
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
  return out;
}

int benchPenetration(const cli::LadderOptions& options, bool json) {
  logLine("penetration ladder on " + options.part);
  const cli::LadderResult result = cli::runPenetrationLadder(options, logLine);
  if (json) std::cout << cli::toJson(result).dump(2) << std::endl;
  else cli::printLadder(result, std::cout);
  return 0;
}

// What `parts info` prints about a part, with its back end built.
std::string partReport(const std::string& name, bool serial) {
  const SamplePart sample = findPart(name);
  PartModel::LoadOptions options;
  options.parallel = !serial;
  const PartModelPtr part = PartModel::fromFile(sample.file, sample.unit, options);
  const MassProperties m = part->massProperties(sample.mass);
  char* text = nullptr;
  std::size_t size = 0;
  FILE* out = open_memstream(&text, &size);
  const Aabb b = part->bounds();
  std::fprintf(out, "part %s (%s)\n", sample.name.c_str(), sample.file.c_str());
  std::fprintf(out, "  faces %d, edges %d, vertices %d, primitive: %s\n", part->faces().Extent(), part->edges().Extent(),
                   part->vertices().Extent(), toString(part->primitive().kind));
  std::fprintf(out, "  bounds [m]: %.6g %.6g %.6g .. %.6g %.6g %.6g\n", b.min.x(), b.min.y(), b.min.z(), b.max.x(),
                   b.max.y(), b.max.z());
  std::fprintf(out, "  volume %.6g m^3, mass %.6g kg, centre of gravity [m] %.6g %.6g %.6g\n", m.volume_m3, m.mass_kg,
                   m.centre_m.x(), m.centre_m.y(), m.centre_m.z());
  std::fprintf(out, "  inertia about the centre [kg m^2]:\n");
  for (int r = 0; r < 3; ++r)
    std::fprintf(out, "    %12.6g %12.6g %12.6g\n", m.inertia_kgm2(r, 0), m.inertia_kgm2(r, 1), m.inertia_kgm2(r, 2));
  // The back end Auto picks, built as a scene would build it.
  const auto built = std::chrono::steady_clock::now();
  const PenetrationModelPtr penetration = makePenetration(part);
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - built).count();
  std::fprintf(out, "  back end: %s\n", autoBackendReason(*part, penetration->name()).c_str());
  const PartLoadTiming& t = part->loadTiming();
  const double loadAfterReading_s = t.total_s - t.read_s;
  std::fprintf(out, "  load %.3f s: read %.3f s, checks %.3f s, all but reading %.3f s (%.3f s per 500 faces); "
                   "back end built in %.3f s\n",
                   t.total_s, t.read_s, t.check_s, loadAfterReading_s, loadAfterReading_s * 500 / part->faces().Extent(),
                   build_s);
  for (const std::string& w : part->warnings()) std::fprintf(out, "  note: %s\n", w.c_str());
  std::fclose(out);
  std::string report(text, size);
  std::free(text);
  return report;
}

// The part's report, or one error line. A damaged file can crash OCCT's readers or make its
// checks loop for minutes: the part is loaded in a child process under a time and memory
// limit (isolated_load.hpp), with OCCT's fault handlers, which only that child needs.
int partInfo(const std::string& name, bool serial, double timeLimit_s) {
  IsolationLimits limits;
  limits.time = std::chrono::milliseconds(std::llround(timeLimit_s * 1e3));
  const std::string report = isolatedLoad(name + ": loading the part", [&] {
    catchOcctFaults();
    try {
      return partReport(name, serial);
    } catch (const GeometryError& e) {  // "solid has no volume": whose?
      const std::string message = e.what();
      throw GeometryError(message.find(name) == std::string::npos ? name + ": " + message : message);
    }
  }, limits);
  std::fputs(report.c_str(), stdout);
  return 0;
}

// The paper's experiment on its cylinder: the transitions, as the operator would hear
// them, and the figures the paper claims (continuity at lift, the eccentric moment).
int graspCylinder(double rate_hz, bool json) {
  const grasp::GraspCylinderResult r = grasp::runGraspCylinder(rate_hz);
  if (json) {
    std::cout << grasp::toJson(r) << std::endl;
    return 0;
  }
  std::printf("grasp-cylinder: the paper's cylinder (0.1 x 0.4 m, %.3g kg) at %.0f Hz\n", r.mass_kg, r.rate_hz);
  for (const auto& t : r.transitions)
    std::printf("  t = %7.4f s  %-14s -> %s\n", t.t, grasp::toString(t.from), grasp::toString(t.to));
  std::printf("  weight %.4f N; vertical wrist force jump at lift %.4f N (%.3f%% of the weight)\n", r.weight_N,
              r.force_jump_at_lift_N, 100 * r.force_jump_at_lift_N / r.weight_N);
  std::printf("  eccentric grasp %.3f m from the centre: moment %.4f N m, expected M g l = %.4f N m\n", r.leverArm_m,
              r.eccentric_moment_Nm, r.expected_eccentric_moment_Nm);
  std::printf("  largest force %.2f N\n", r.max_force_N);
  return 0;
}

// The resultant-force paper's experiment (section 6): both methods, Tables 1-2's figures,
// optionally Fig. 8 as SVG.
int shake(bool json, const std::string& plotFile) {
  const grasp::ShakeResult r = grasp::runShakeExperiment();
  if (!plotFile.empty()) {
    std::ofstream out(plotFile);
    out << grasp::toSvg(r);
    if (!out) throw std::runtime_error("could not write " + plotFile);
  }
  if (json) {
    std::cout << grasp::toJson(r) << std::endl;
    return 0;
  }
  const grasp::ShakeConfig& c = r.config;
  std::printf("shake: block %.0f x %.0f cm, %.3g kg, g = %.2g m/s^2, springs %.0f N/m, friction %.2g\n",
              100 * c.width, 100 * c.height, c.mass, c.gravity, c.stiffness, c.friction);
  std::printf("  subject: target grasping force %.3g N; %d shakes of %.0f mm peak to peak at %.3g Hz, then %.3g s rest\n",
              r.target_grasp_force_N, c.shakes, 2000 * c.amplitude, c.frequency, c.rest);
  std::printf("  %-13s %12s %12s %12s %12s %12s\n", "method", "f_g mean N", "f_g std N", "dist mean cm",
              "dist std cm", "max |f_r| N");
  for (const auto& [name, m] : {std::pair<const char*, const grasp::ShakeMethodResult&>{"conventional", r.conventional},
                                {"proposed", r.proposed}})
    std::printf("  %-13s %12.3f %12.3f %12.3f %12.4f %12.3f\n", name, m.grasp_force_mean_N, m.grasp_force_std_N,
                100 * m.distance_mean_m, 100 * m.distance_std_m, m.resultant_max_N);
  if (!plotFile.empty()) std::printf("  plot: %s\n", plotFile.c_str());
  return 0;
}

// The demonstration: the paper's grasp scenario, then the penetration ladder (fewer
// queries) on the paper's cylinder and the machined block.
int demo() {
  graspCylinder(2000.0, false);
  std::cout << std::endl;
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
  hg::runningImage();  // where this binary is, fixed now: a later rebuild or upgrade cannot move its data
  CLI::App app{"HapticGrasp: feel and handle the parts of a CAD model with a haptic arm"};
  app.require_subcommand(1);

  app.add_subcommand("demo", "Run the demonstration: the paper's grasp of the cylinder, then the penetration ladder");

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
  penetration->add_option("--repeat", ladder.repeat, "Time each query N times, keep the fastest (a busy machine)")
      ->capture_default_str()->check(CLI::PositiveNumber);
  penetration->add_option("--backends", ladder.backends, "Only these back ends (exact, analytic, mesh, field)")
      ->delimiter(',')
      ->check(CLI::IsMember({"exact", "analytic", "mesh", "field"}));
  penetration->add_flag("--json", json, "Print JSON");

  CLI::App* servoBench =
      bench->add_subcommand("servo", "The real servo thread: the simulated arm (or a scripted hand) grasps and lifts a part");
  servo::ServoBenchOptions servoOptions;
  servoBench->add_option("--rate", servoOptions.rate_hz, "Servo rate, Hz (50-10000)")->capture_default_str();
  servoBench->add_option("--seconds", servoOptions.seconds, "How long to run")->capture_default_str();
  servoBench->add_option("--part", servoOptions.part, "Sample part (cylinder, block, loft, plate) or a .brep/.step file (mm)")
      ->capture_default_str();
  servoBench->add_option("--device", servoOptions.device, "Who holds the part: the simulated master arm or a scripted hand")
      ->capture_default_str()
      ->check(CLI::IsMember({"arm", "scripted"}));
  servoBench->add_option("--backend", servoOptions.backend, "Penetration back end (auto: analytic for primitives, exact otherwise)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "exact", "analytic", "mesh"}));
  servoBench->add_option("--method", servoOptions.method,
                         "Grasp method: the first paper's two-finger state machine or the resultant-force paper's "
                         "multi-finger method")
      ->capture_default_str()
      ->check(CLI::IsMember({"two-finger", "multi-finger"}));
  servoBench->add_option("--fingers", servoOptions.fingers,
                         "Fingertips for the multi-finger method (the arm has 2; the scripted hand 1-5)")
      ->capture_default_str()
      ->check(CLI::Range(1, 5));
  servoBench->add_flag("--contact", servoOptions.contact,
                       "A floor plate under the part and part-to-part contact: the put-down meets the floor");
  servoBench->add_flag("--json", json, "Print JSON");

  CLI::App* sceneBench = bench->add_subcommand(
      "scene", "A scene of every solid of a file, repeated: start, first touch, background build, servo cost");
  servo::SceneBenchOptions sceneOptions;
  sceneBench->add_option("--part", sceneOptions.part, "A .step/.brep file (an assembly) or a sample part")->required();
  sceneBench->add_option("--copies", sceneOptions.copies, "The file's solids this many times side by side")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  sceneBench->add_option("--seconds", sceneOptions.seconds, "Servo time at least (longer until every model is built)")
      ->capture_default_str();
  sceneBench->add_option("--rate", sceneOptions.rate_hz, "Servo rate, Hz (50-10000)")->capture_default_str();
  sceneBench->add_option("--workers", sceneOptions.workers, "Threads building models")->capture_default_str()->check(
      CLI::Range(1, 64));
  sceneBench->add_flag("!--no-sharing", sceneOptions.share,
                       "Build every copy's models apart, as if no two parts were the same shape");
  sceneBench->add_option("--load", sceneOptions.load,
                         "How each model loads: shape (as read, here), text (its BREP text, here: the workbench without "
                         "its loader), loader (its BREP text in the loader process: the workbench's way)")
      ->capture_default_str()
      ->check(CLI::IsMember({"shape", "text", "loader"}));
  sceneBench->add_flag("!--no-pin", sceneOptions.pin,
                       "Leave the servo thread and the model builders to the scheduler (no CPU of its own)");
  sceneBench->add_flag("--json", json, "Print JSON");

  CLI::App* contactBench = bench->add_subcommand(
      "contact", "Part-to-part contact: a part carried onto and into two copies of itself, compute per tick");
  cli::ContactBenchOptions contactOptions;
  contactBench->add_option("--part", contactOptions.part, "A .step/.brep file (mm)")->required();
  contactBench->add_option("--rate", contactOptions.rate_hz, "Servo rate, Hz")->capture_default_str()->check(
      CLI::Range(50.0, 10000.0));
  contactBench->add_option("--seconds", contactOptions.seconds, "How long")->capture_default_str()->check(
      CLI::Range(0.01, 3600.0));
  contactBench->add_option("--points", contactOptions.points, "The carried part's shell points")
      ->capture_default_str()
      ->check(CLI::Range(8, 2048));
  contactBench->add_flag("--json", json, "Print JSON");

  // Sessions: record, recording info, replay, report.
  servo::ServoBenchOptions recordOptions;
  recordOptions.device = "scripted";
  recordOptions.seconds = 5;
  CLI::App* recordCmd = app.add_subcommand("record", "Run the real servo thread with a device and record the session (MCAP)");
  recordCmd->add_option("--device", recordOptions.device, "A scripted hand or the simulated master arm")
      ->capture_default_str()->check(CLI::IsMember({"scripted", "arm"}));
  recordCmd->add_option("--part", recordOptions.part, "Sample part (cylinder, block, loft, plate) or a .brep/.step file (mm)")
      ->capture_default_str();
  recordCmd->add_option("--method", recordOptions.method, "Grasp method")
      ->capture_default_str()->check(CLI::IsMember({"two-finger", "multi-finger"}));
  recordCmd->add_option("--fingers", recordOptions.fingers, "Fingertips of the multi-finger method (1-5)")->capture_default_str();
  recordCmd->add_option("--rate", recordOptions.rate_hz, "Servo rate, Hz (50-10000)")->capture_default_str();
  recordCmd->add_option("--seconds", recordOptions.seconds, "How long to record")->capture_default_str();
  recordCmd->add_option("-o,--output", recordOptions.recordPath, "The recording to write (.mcap)")->required();
  recordCmd->add_flag("--contact", recordOptions.contact, "A floor plate under the part and part-to-part contact");
  recordCmd->add_flag("--json", json, "Print JSON");
  servoBench->add_option("--record", servoOptions.recordPath, "Record the benchmark's session to this MCAP file");

  CLI::App* recordingCmd = app.add_subcommand("recording", "Inspect recordings");
  recordingCmd->require_subcommand(1);
  std::string recordingPath, reportOutput;
  CLI::App* recordingInfoCmd = recordingCmd->add_subcommand("info", "What a recording holds (works on truncated files)");
  recordingInfoCmd->add_option("file", recordingPath, "A .mcap recording")->required();
  recordingInfoCmd->add_flag("--json", json, "Print JSON");
  double recordingTimeLimit_s = 60, replayTimeLimit_s = 600;
  recordingInfoCmd->add_option("--time-limit", recordingTimeLimit_s, "Seconds after which reading is given up; 0: none")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  bool replayCheck = false;
  CLI::App* replayCmd = app.add_subcommand("replay", "Re-simulate a recording through the same grasp engine");
  replayCmd->add_option("file", recordingPath, "A .mcap recording")->required();
  replayCmd->add_flag("--check", replayCheck, "Compare with what was recorded; exit 1 unless identical");
  replayCmd->add_flag("--json", json, "Print JSON");
  replayCmd->add_option("--time-limit", replayTimeLimit_s, "Seconds after which the replay is given up; 0: none")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  CLI::App* reportCmd = app.add_subcommand("report", "Write a recording's report as one self-contained HTML page");
  reportCmd->add_option("file", recordingPath, "A .mcap recording")->required();
  reportCmd->add_option("-o,--output", reportOutput, "The report to write (.html)")->required();

  CLI::App* devices = app.add_subcommand("devices", "List HID devices and which back end or layout matches each");
  bool udevRule = false;
  devices->add_flag("--udev-rule", udevRule,
                    "Print the udev rule that gives the logged-in user the devices HapticGrasp drives "
                    "(the package installs it as /usr/lib/udev/rules.d/70-hapticgrasp.rules)");
  CLI::App* doctorCmd = app.add_subcommand(
      "doctor", "What this machine allows and lacks: real time, locked memory, HID access, FreeCAD, the workbench, audio");
  doctorCmd->add_flag("--json", json, "Print JSON");

  servo::SoakOptions soakOptions;
  CLI::App* soakCmd = app.add_subcommand(
      "soak", "The real servo thread for M minutes over the sample parts, both methods, a wandering hand and injected "
              "faults (silence, NaN/Inf, stalls, unplugging, model swaps), recorded; exit 1 unless every fault is handled "
              "with no NaN, no allocation and flat memory");
  soakCmd->add_option("--minutes", soakOptions.minutes, "How long")->capture_default_str()->check(CLI::Range(0.01, 1440.0));
  soakCmd->add_option("--rate", soakOptions.rate_hz, "Servo rate, Hz")->capture_default_str()->check(CLI::Range(50.0, 10000.0));
  soakCmd->add_option("--seed", soakOptions.seed, "Random seed (faults, hand, swaps)")->capture_default_str();
  soakCmd->add_option("--faults-per-minute", soakOptions.faultsPerMinute, "Device faults a minute")
      ->capture_default_str()->check(CLI::Range(0.0, 600.0));
  bool soakNoRecord = false;
  soakCmd->add_flag("--no-record", soakNoRecord, "Do not record the segments");
  soakCmd->add_flag("--json", json, "Print JSON");

  CLI::App* experiment = app.add_subcommand("experiment", "Reproduce the papers' experiments");
  experiment->require_subcommand(1);
  double rate_hz = 2000.0;
  CLI::App* graspCylinderCmd =
      experiment->add_subcommand("grasp-cylinder", "Maekawa & Hollerbach's grasp of the 2 kg cylinder (Fig. 6)");
  graspCylinderCmd->add_option("--rate", rate_hz, "Servo rate, Hz")->capture_default_str()->check(CLI::PositiveNumber);
  graspCylinderCmd->add_flag("--json", json, "Print JSON");
  std::string shakePlot;
  CLI::App* shakeCmd = experiment->add_subcommand(
      "shake", "The resultant-force paper's shaking experiment (section 6): conventional vs proposed");
  shakeCmd->add_flag("--json", json, "Print JSON");
  shakeCmd->add_option("--plot", shakePlot, "Write grasping force and finger distance against time (Fig. 8) as SVG");

  CLI::App* pegInHoleCmd = experiment->add_subcommand(
      "peg-in-hole", "Part-to-part contact: a peg into a hole 0.1 mm wider, and a strike on a 0.5 mm plate at 1 m/s");
  pegInHoleCmd->add_option("--rate", rate_hz, "Servo rate, Hz")->capture_default_str()->check(CLI::PositiveNumber);
  pegInHoleCmd->add_flag("--json", json, "Print JSON");

  CLI::App* parts = app.add_subcommand("parts", "Inspect parts");
  parts->require_subcommand(1);
  std::string partName;
  CLI::App* info = parts->add_subcommand("info", "Topology, bounds, mass properties of a part, which back end answers it and why");
  info->add_option("part", partName, "Sample part name or .brep/.step file (mm)")->required();
  bool serialLoad = false;
  info->add_flag("--serial", serialLoad, "Check the part on one thread, as the FreeCAD workbench loads it");
  double partTimeLimit_s = IsolationLimits().time.count() / 1e3;
  info->add_option("--time-limit", partTimeLimit_s,
                   "Seconds after which loading the part is given up (a damaged file can hang the reader); 0: none")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();

  CLI11_PARSE(app, argc, argv);
  try {
    if (app.got_subcommand("demo")) return demo();
    if (penetration->parsed()) return benchPenetration(ladder, json);
    if (info->parsed()) return partInfo(partName, serialLoad, partTimeLimit_s);
    if (graspCylinderCmd->parsed()) return graspCylinder(rate_hz, json);
    if (shakeCmd->parsed()) return shake(json, shakePlot);
    if (pegInHoleCmd->parsed()) return cli::pegInHole(rate_hz, json);
    if (contactBench->parsed()) return cli::benchContact(contactOptions, json);
    if (servoBench->parsed()) return cli::benchServo(servoOptions, json);
    if (sceneBench->parsed()) return cli::benchScene(sceneOptions, json);
    if (devices->parsed()) return udevRule ? cli::printUdevRule() : cli::listDevices();
    if (doctorCmd->parsed()) return cli::doctor(json);
    if (soakCmd->parsed()) {
      soakOptions.record = !soakNoRecord;
      return cli::soak(soakOptions, json);
    }
    if (recordCmd->parsed()) return cli::record(recordOptions, json);
    if (recordingInfoCmd->parsed()) return cli::recordingInfo(recordingPath, json, recordingTimeLimit_s);
    if (replayCmd->parsed()) return cli::replay(recordingPath, replayCheck, json, replayTimeLimit_s);
    if (reportCmd->parsed()) return cli::report(recordingPath, reportOutput);
  } catch (const std::exception& e) {  // GeometryError, HidError, invalid_argument: one line
    std::cerr << "hapticgrasp: " << oneLine(e.what()) << std::endl;
    return 2;
  }
  return 0;
}
