#include "hapticgrasp/servo/realtime_access.hpp"

#include <linux/capability.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace hg::servo {
namespace {

long softLimit(int resource) {
  rlimit r{};
  if (getrlimit(resource, &r) != 0) return 0;
  return r.rlim_cur == RLIM_INFINITY ? -1 : static_cast<long>(r.rlim_cur);
}

// The effective capability set, from the kernel (libcap is not needed for one bit).
bool hasCapability(int capability) {
  __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
  __user_cap_data_struct data[2]{};
  if (syscall(SYS_capget, &header, data) != 0) return false;
  return (data[capability / 32].effective & (1u << (capability % 32))) != 0;
}

std::string groupFix() {
  return std::string("add your user to the group ") + kRealtimeGroup + " (sudo usermod -aG " + kRealtimeGroup +
         " $USER) and log in again: the package's " + kRealtimeLimitsFile +
         " grants that group real-time priority and locked memory";
}

void* trySchedFifo(void* arg) {
  auto* access = static_cast<RealtimeAccess*>(arg);
  sched_param param{};
  param.sched_priority = access->priority;
  const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  access->granted = rc == 0;
  if (rc != 0) access->why = std::string("SCHED_FIFO refused (") + std::strerror(rc) + ")";
  return nullptr;
}

}  // namespace

RealtimeAccess probeRealtime(int priority) noexcept {
  RealtimeAccess a;
  a.priority = priority;
  a.rtprioLimit = softLimit(RLIMIT_RTPRIO);
  a.capSysNice = hasCapability(CAP_SYS_NICE);
  pthread_t thread;
  if (pthread_create(&thread, nullptr, trySchedFifo, &a) != 0) {
    a.why = "could not start a thread to try SCHED_FIFO";
  } else {
    pthread_join(thread, nullptr);
  }
  try {
    if (a.granted) {
      a.why = "SCHED_FIFO " + std::to_string(priority) +
              (a.capSysNice ? " granted (CAP_SYS_NICE)" : " granted (RLIMIT_RTPRIO " +
                                                               (a.rtprioLimit < 0 ? std::string("unlimited")
                                                                                  : std::to_string(a.rtprioLimit)) +
                                                               ")");
    } else {
      a.why += ": RLIMIT_RTPRIO is " + (a.rtprioLimit < 0 ? std::string("unlimited") : std::to_string(a.rtprioLimit)) +
               " (" + std::to_string(priority) + " needed) and no CAP_SYS_NICE";
      a.fix = groupFix();
    }
  } catch (...) {  // out of memory building the text: the fields still say it
  }
  return a;
}

MemoryLockAccess probeMemoryLock() noexcept {
  MemoryLockAccess m;
  const long limit = softLimit(RLIMIT_MEMLOCK);
  m.limitBytes = limit;
  m.granted = mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
  const int error = errno;
  if (m.granted) munlockall();
  try {
    const std::string limitText = limit < 0 ? "unlimited" : std::to_string(limit / 1024) + " KiB";
    if (m.granted) {
      m.why = "mlockall granted (RLIMIT_MEMLOCK " + limitText + (hasCapability(CAP_IPC_LOCK) ? ", CAP_IPC_LOCK)" : ")");
    } else {
      m.why = std::string("mlockall refused (") + std::strerror(error) + "): RLIMIT_MEMLOCK is " + limitText +
              ", the process's pages exceed it; page faults can then stall the servo thread";
      m.fix = groupFix();
    }
  } catch (...) {
  }
  return m;
}

std::string realtimeAdvice(const RealtimeAccess& access) {
  if (access.granted) return access.why;
  return access.why + "; to fix it, " + access.fix;
}

}  // namespace hg::servo
