#include "formats/temp_file_registry.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace rad {

namespace {

// A slot's states. Only kFree slots are written by registerTempFile and only kLive ones read
// by the handler, which claims a slot (kLive -> kClaimed) before reading its path, so the path
// it unlinks is never one being written or freed.
enum SlotState : int { kFree = 0, kFilling = 1, kLive = 2, kClaimed = 3 };

struct Slot {
  std::atomic<int> state{kFree};
  char* path = nullptr;  // malloc'ed copy, owned while kFilling / kLive / kClaimed
};

Slot gSlots[kMaxRegisteredTempFiles];
static_assert(std::atomic<int>::is_always_lock_free, "the handler needs lock-free atomics");

constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void removeTempFilesAndDie(int sig) {
  const int savedErrno = errno;
  for (Slot& slot : gSlots) {
    int live = kLive;
    if (slot.state.compare_exchange_strong(live, kClaimed)) ::unlink(slot.path);
  }
  errno = savedErrno;
  // SA_RESETHAND restored the default action; the signal is blocked while this handler runs
  // and is delivered, killing the process, when it returns.
  ::raise(sig);
}

void installHandlers() {
  for (int sig : kSignals) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) != 0) continue;
    const bool untouched = !(old.sa_flags & SA_SIGINFO) && old.sa_handler == SIG_DFL;
    if (!untouched) continue;  // ignored on purpose, or someone else's handler
    struct sigaction action {};
    action.sa_handler = removeTempFilesAndDie;
    sigfillset(&action.sa_mask);  // no other of our signals runs the loop twice at once
    action.sa_flags = SA_RESETHAND | SA_RESTART;
    ::sigaction(sig, &action, nullptr);
  }
}

}  // namespace

int registerTempFile(const std::string& path) {
  static std::once_flag installed;
  std::call_once(installed, installHandlers);
  for (int i = 0; i < kMaxRegisteredTempFiles; ++i) {
    int free = kFree;
    if (!gSlots[i].state.compare_exchange_strong(free, kFilling)) continue;
    gSlots[i].path = ::strdup(path.c_str());
    if (!gSlots[i].path) {
      gSlots[i].state.store(kFree);
      return -1;
    }
    gSlots[i].state.store(kLive);
    return i;
  }
  return -1;
}

void unregisterTempFile(int slot) {
  if (slot < 0 || slot >= kMaxRegisteredTempFiles) return;
  Slot& s = gSlots[slot];
  int live = kLive;
  while (!s.state.compare_exchange_strong(live, kFilling)) {
    live = kLive;
    ::pause();  // claimed by the handler: the process is ending
  }
  std::free(s.path);
  s.path = nullptr;
  s.state.store(kFree);
}

}  // namespace rad
