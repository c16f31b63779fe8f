// Writes a representative session recording with hg::session::McapWriter, for checking
// our files with other readers (tests/mcap: the reference reader, @mcap/core):
//   mcap_sample <out.mcap> [--seconds S]
// Two schemas, three channels (servo ticks at 2 kHz, fingertips at 500 Hz, a log at 10 Hz)
// over S seconds (default 3, so several chunks), a part as an attachment and a session
// metadata record. Prints what it wrote as one JSON line (the fields validate.mjs prints).
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "hapticgrasp/session/mcap_writer.hpp"

namespace {

using hg::session::McapWriter;

constexpr std::uint64_t kStart_ns = 1'700'000'000'000'000'000ull;  // a fixed wall time

const char* kTickSchema = R"({"type":"object","properties":{"tick":{"type":"integer"},
"q":{"type":"array","items":{"type":"number"}},"force_N":{"type":"array","items":{"type":"number"}}}})";
const char* kLogSchema = R"({"title":"foxglove.Log","type":"object","properties":{
"timestamp":{"type":"object"},"level":{"type":"integer"},"message":{"type":"string"},
"name":{"type":"string"},"file":{"type":"string"},"line":{"type":"integer"}}})";

std::string tickJson(std::uint64_t tick) {
  char text[512];
  const double t = static_cast<double>(tick) / 2000.0;
  std::snprintf(text, sizeof text,
                R"({"tick":%llu,"q":[%.9f,%.9f,%.9f,%.9f,%.9f,%.9f],"force_N":[%.6f,%.6f,%.6f]})",
                static_cast<unsigned long long>(tick), 0.1 * t, 0.2 * t, -0.05 * t, 1e-3 * tick,
                0.5, -0.25, 0.01 * (tick % 97), -0.02 * (tick % 13), 9.81);
  return text;
}

std::string fingertipsJson(std::uint64_t n) {
  char text[256];
  std::snprintf(text, sizeof text,
                R"({"index":[%.6f,0.02,0.1],"thumb":[%.6f,-0.02,0.1],"penetration_m":%.7f})",
                1e-4 * static_cast<double>(n % 200), -1e-4 * static_cast<double>(n % 200),
                1e-6 * static_cast<double>(n % 31));
  return text;
}

std::string logJson(std::uint64_t n, std::uint64_t time_ns) {
  char text[256];
  std::snprintf(
      text, sizeof text,
      R"({"timestamp":{"sec":%llu,"nsec":%llu},"level":2,"message":"grasp state %llu","name":"servo","file":"grasp.cpp","line":42})",
      static_cast<unsigned long long>(time_ns / 1'000'000'000),
      static_cast<unsigned long long>(time_ns % 1'000'000'000),
      static_cast<unsigned long long>(n % 4));
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && !(argc == 4 && std::string(argv[2]) == "--seconds")) {
    std::fprintf(stderr, "usage: mcap_sample <out.mcap> [--seconds S]\n");
    return 2;
  }
  const double seconds = argc == 4 ? std::atof(argv[3]) : 3.0;
  const auto ticks = static_cast<std::uint64_t>(seconds * 2000.0);
  try {
    McapWriter::Options options;
    options.chunkSeconds = 0.5;
    McapWriter w(argv[1], options);
    const auto tick = w.addSchema("hapticgrasp.Tick", "jsonschema", kTickSchema);
    const auto log = w.addSchema("foxglove.Log", "jsonschema", kLogSchema);
    const auto ticksChannel = w.addChannel(tick, "/servo/tick", "json", {{"rate_hz", "2000"}});
    const auto tipsChannel = w.addChannel(tick, "/servo/fingertips", "json");
    const auto logChannel = w.addChannel(log, "/log", "json");
    std::map<std::string, std::uint64_t> topics;
    w.metadata("session",
               {{"operator", "sample"}, {"device", "simulated"}, {"method", "two-finger"}});
    for (std::uint64_t i = 0; i < ticks; ++i) {
      const std::uint64_t t = kStart_ns + i * 500'000;  // 2 kHz
      w.write(ticksChannel, static_cast<std::uint32_t>(i), t, t, tickJson(i));
      ++topics["/servo/tick"];
      if (i % 4 == 0) {
        w.write(tipsChannel, static_cast<std::uint32_t>(i / 4), t, t, fingertipsJson(i / 4));
        ++topics["/servo/fingertips"];
      }
      if (i % 200 == 0) {
        w.write(logChannel, static_cast<std::uint32_t>(i / 200), t, t, logJson(i / 200, t));
        ++topics["/log"];
      }
      if (i == ticks / 2)
        w.attach(
            "cylinder.brep", "application/octet-stream", t, kStart_ns - 1'000'000'000,
            "DBRep_DrawableShape\nCASCADE Topology V1, (c) Matra-Datavision\n(a sample part)\n");
    }
    if (ticks == 0)
      w.attach("cylinder.brep", "application/octet-stream", kStart_ns, 0, "(empty session)");
    w.close();
    std::printf(R"({"file": "%s", "messages": %llu, "topics": {)", argv[1],
                static_cast<unsigned long long>(w.messages()));
    const char* comma = "";
    for (const auto& [topic, count] : topics) {
      std::printf(R"(%s"%s": %llu)", comma, topic.c_str(), static_cast<unsigned long long>(count));
      comma = ", ";
    }
    std::printf(R"(}, "attachments": 1, "metadata": 1, "chunks": %llu, "bytes": %llu})"
                "\n",
                static_cast<unsigned long long>(w.chunks()),
                static_cast<unsigned long long>(w.bytes()));
  } catch (const hg::session::McapError& e) {
    std::fprintf(stderr, "mcap_sample: %s\n", e.what());
    return 1;
  }
  return 0;
}
