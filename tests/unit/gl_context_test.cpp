#include "libcommon/gl/gl_context.h"

#include <pthread.h>

#include <atomic>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace rad {
namespace {

std::atomic<int> forks{0};

// The first context of a process is probed in a child process (gl_context.cpp). That child
// had been a fork, made from whichever thread built the first context while the others ran:
// the 10k hall's rad-movies hung there, the forked child waiting on a glibc lock that a thread
// of the parent had held at the fork. The child is now a new copy of the program, which
// inherits no lock: no fork at all. (This binary makes no other context before this test:
// ctest runs each test in a process of its own.)
TEST(GlContext, FirstContextOnAWorkerThreadIsProbedWithoutAFork) {
  ASSERT_EQ(pthread_atfork([] { ++forks; }, nullptr, nullptr), 0);
  std::atomic<bool> stop{false};
  std::thread busy([&] {  // another thread at work meanwhile, as the tools' workers are
    while (!stop) {
      std::string s(64, 'x');
      (void)s;
    }
  });
  std::string renderer, failure;
  std::thread worker([&] {
    try {
      GlContext context;
      renderer = context.renderer();
    } catch (const std::exception& e) {
      failure = e.what();
    }
  });
  worker.join();
  stop = true;
  busy.join();
  EXPECT_EQ(failure, "");
  EXPECT_NE(renderer, "");
  EXPECT_EQ(forks.load(), 0) << "the context probe forked a multithreaded process";
}

}  // namespace
}  // namespace rad
