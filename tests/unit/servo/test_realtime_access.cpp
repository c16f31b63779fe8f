// What the servo thread may get is found by trying it: the probe's answer follows the
// kernel's rule (CAP_SYS_NICE or RLIMIT_RTPRIO at the priority; CAP_IPC_LOCK or a large
// enough RLIMIT_MEMLOCK), and a user without them is told why and how to get them. The
// refused case runs in a forked child that lowers its limits (and, under root, gives up
// root), as a normal user logs in without the group.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>

#include "hapticgrasp/servo/realtime_access.hpp"
#include "hapticgrasp/sanitized.hpp"

namespace hg::servo {
namespace {

// Runs `body` in a child as an unprivileged user with RLIMIT_RTPRIO 0 and a 64 KiB
// RLIMIT_MEMLOCK; returns its exit code (0: every check in it held).
template <typename Body>
int asUnprivilegedChild(Body body) {
  const pid_t pid = fork();
  if (pid == 0) {
    const rlimit none{0, 0}, small{64 * 1024, 64 * 1024};
    if (setrlimit(RLIMIT_RTPRIO, &none) != 0 || setrlimit(RLIMIT_MEMLOCK, &small) != 0) _exit(90);
    if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(91);  // nobody: no capabilities
    _exit(body());
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 99;
}

TEST(RealtimeAccess, FollowsTheKernelsRule) {
  const RealtimeAccess a = probeRealtime(80);
  EXPECT_EQ(a.priority, 80);
  EXPECT_EQ(a.granted, a.capSysNice || a.rtprioLimit < 0 || a.rtprioLimit >= 80) << a.why;
  EXPECT_FALSE(a.why.empty());
  EXPECT_EQ(a.fix.empty(), a.granted);
  EXPECT_EQ(realtimeAdvice(a).find(a.why), 0u);
}

TEST(RealtimeAccess, AUserWithoutTheGroupIsToldWhyAndHow) {
  const int rc = asUnprivilegedChild([] {
    const RealtimeAccess a = probeRealtime(80);
    if (a.granted || a.capSysNice || a.rtprioLimit != 0) return 1;
    if (a.why.find("SCHED_FIFO refused") == std::string::npos) return 2;
    if (a.why.find("RLIMIT_RTPRIO is 0 (80 needed)") == std::string::npos) return 3;
    if (a.fix.find("usermod -aG hapticgrasp") == std::string::npos) return 4;
    if (realtimeAdvice(a).find(kRealtimeLimitsFile) == std::string::npos) return 5;
    return 0;
  });
  EXPECT_EQ(rc, 0);
}

TEST(MemoryLockAccess, IsTriedAndUndone) {
#ifdef HG_SANITIZED
  GTEST_SKIP() << "the sanitizers make mlockall a no-op that succeeds (their shadow memory cannot be locked)";
#endif
  const MemoryLockAccess m = probeMemoryLock();
  EXPECT_FALSE(m.why.empty());
  EXPECT_EQ(m.fix.empty(), m.granted);
  const int rc = asUnprivilegedChild([] {
    const MemoryLockAccess m = probeMemoryLock();
    if (m.granted || m.limitBytes != 64 * 1024) return 1;
    if (m.why.find("RLIMIT_MEMLOCK is 64 KiB") == std::string::npos) return 2;
    if (m.fix.find("group hapticgrasp") == std::string::npos) return 3;
    return 0;
  });
  EXPECT_EQ(rc, 0);
}

}  // namespace
}  // namespace hg::servo
