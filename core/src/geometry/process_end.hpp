#pragma once
// How an isolated load says its child process ended (isolated_load.cpp, loader_process.cpp):
// "crashed (SIGSEGV, Segmentation fault)", "did not finish within 8 s".
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>

namespace hg::geometry {

inline std::string signalName(int signal) {
  const char* abbrev = sigabbrev_np(signal);
  return (abbrev ? "SIG" + std::string(abbrev) : "signal " + std::to_string(signal)) + ", " + strsignal(signal);
}

inline std::string secondsText(std::chrono::milliseconds time) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", time.count() / 1e3);
  return text;
}

}  // namespace hg::geometry
