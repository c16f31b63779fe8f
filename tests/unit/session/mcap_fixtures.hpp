#pragma once
// Shared by the MCAP writer and reader tests: a per-test temporary directory, whole-file
// helpers, and a sample recording whose every message is known.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "file_fixtures.hpp"
#include "hapticgrasp/session/mcap_writer.hpp"
#include "temp_dir.hpp"

namespace hg::session::test {

// A fresh directory per test, removed with everything in it afterwards; whole files.
using hg::test::readFile;
using hg::test::TempDir;
using hg::test::writeFile;

// One message as the sample wrote it.
struct SampleMessage {
  std::uint16_t channel;
  std::uint32_t sequence;  // unique across the file: the message's number
  std::uint64_t logTime_ns;
  std::string data;
};

// A payload that differs per message and compresses like real samples (partly).
inline std::string samplePayload(std::uint32_t n, std::size_t bytes) {
  std::string s(bytes, '\0');
  std::uint64_t x = 0x9E3779B97F4A7C15ull * (n + 1);
  for (std::size_t i = 0; i < bytes; ++i) {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    s[i] = static_cast<char>(i % 4 == 0 ? (x & 0xFF) : (n + i) & 0x0F);
  }
  return s;
}

struct Sample {
  std::vector<SampleMessage> messages;
  std::uint64_t chunks = 0;
  std::uint64_t bytes = 0;
};

// Two schemas, three channels, `count` messages at 1 kHz from t0 (channel 1 every second
// message, 2 and 3 every fourth), with `extras` an attachment after the first third and a
// metadata record after the second.
inline Sample writeSample(const std::string& path, std::uint32_t count,
                          McapWriter::Options options = {},
                          std::uint64_t t0_ns = 1'700'000'000'000'000'000ull, bool extras = true) {
  Sample sample;
  McapWriter w(path, options);
  const auto s1 = w.addSchema("hapticgrasp.Tick", "jsonschema", R"({"type":"object"})");
  const auto s2 = w.addSchema("foxglove.Log", "jsonschema", R"({"type":"object","title":"Log"})");
  const std::uint16_t ch[3] = {w.addChannel(s1, "/tick", "json", {{"rate_hz", "1000"}}),
                               w.addChannel(s1, "/tick/forces", "json"),
                               w.addChannel(s2, "/log", "json", {{"a", "1"}, {"b", "2"}})};
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint16_t channel = i % 4 == 3 ? ch[2] : ch[i % 2];
    const std::uint64_t t = t0_ns + std::uint64_t{i} * 1'000'000;
    std::string data = samplePayload(i, 40 + i % 200);
    w.write(channel, i, t, t + 7, data);
    sample.messages.push_back({channel, i, t, std::move(data)});
    if (extras && i == count / 3)
      w.attach("part.brep", "application/octet-stream", t, t - 5, samplePayload(999, 5000));
    if (extras && i == 2 * count / 3)
      w.metadata("session", {{"operator", "test"}, {"device", "scripted"}});
  }
  w.close();
  sample.chunks = w.chunks();
  sample.bytes = w.bytes();
  return sample;
}

}  // namespace hg::session::test
