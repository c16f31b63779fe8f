#pragma once
// What this process may do for the servo thread's timing, found by trying it, and how a
// user gets what is missing. Linux grants SCHED_FIFO to a thread whose user has
// CAP_SYS_NICE (root) or an RLIMIT_RTPRIO soft limit at or above the priority asked, and
// lets mlockall() lock all current and future pages with CAP_IPC_LOCK or an unlimited
// RLIMIT_MEMLOCK. Desktop audio software gets both for normal users the same way this
// project's package does: a system group and a limits.d entry granting it (pam_limits
// applies it at login). Used by `hapticgrasp doctor` and the workbench's panel.
#include <string>

namespace hg::servo {

// The group and the limits.d file the package installs (packaging/): one place for both.
inline constexpr const char* kRealtimeGroup = "hapticgrasp";
inline constexpr const char* kRealtimeLimitsFile = "/etc/security/limits.d/95-hapticgrasp.conf";

struct RealtimeAccess {
  bool granted = false;   // a thread of this process got SCHED_FIFO at `priority` (tried)
  int priority = 0;
  long rtprioLimit = 0;   // RLIMIT_RTPRIO soft limit; -1: unlimited
  bool capSysNice = false;
  std::string why;        // one line: how it is granted, or why not
  std::string fix;        // what to do; "" when granted
};

struct MemoryLockAccess {
  bool granted = false;   // mlockall(MCL_CURRENT | MCL_FUTURE) succeeded (tried, then undone)
  long long limitBytes = 0;  // RLIMIT_MEMLOCK soft limit; -1: unlimited
  std::string why, fix;
};

// Tries SCHED_FIFO at `priority` on a short-lived thread of its own (the caller's
// scheduling is untouched). Never throws.
RealtimeAccess probeRealtime(int priority = 80) noexcept;
// Tries mlockall and undoes it with munlockall: call it only when no servo loop of this
// process holds the lock. Never throws.
MemoryLockAccess probeMemoryLock() noexcept;

// The one line a user reads when the servo thread did not get SCHED_FIFO (the scheduler
// text ServoLoop::scheduler() gives): why, and the fix above.
std::string realtimeAdvice(const RealtimeAccess& access);

}  // namespace hg::servo
