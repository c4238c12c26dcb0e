// rad-global as a stage (global_stage.h): the render farm's key windows (--window) and the
// command line a --merge run records (the whole run's).
#include "libcommon/radiosity/global_stage.h"

#include <gtest/gtest.h>

#include "libcommon/core/error.h"

namespace rad {
namespace {

// Frames 0-12 at key step 4: keys at frames 0, 4, 8, 12.
TEST(GlobalStage, WindowKeysAreTheRunsKeysWithinTheFrames) {
  const FrameRange frames{0, 12};
  auto keys = [&](const std::string& w) {
    const KeyIndexRange r = windowKeys(frames, 4, w);
    return std::make_pair(r.first, r.last);
  };
  EXPECT_EQ(keys("0-5"), std::make_pair(size_t(0), size_t(1)));
  EXPECT_EQ(keys("6-12"), std::make_pair(size_t(2), size_t(3)));
  EXPECT_EQ(keys("4-4"), std::make_pair(size_t(1), size_t(1)));
  EXPECT_EQ(keys("0-12"), std::make_pair(size_t(0), size_t(3)));
  for (const char* bad : {"1-3", "13-20", "5-2", "x", "3", "0-5x2", "-1-4"}) {
    try {
      windowKeys(frames, 4, bad);
      ADD_FAILURE() << bad << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::kUsage) << bad;
      EXPECT_NE(std::string(e.what()).find(std::string("--window ") + bad), std::string::npos)
          << e.what();
    }
  }
}

// The farm's windows (--print-windows) tile the frames and each holds at least one key frame,
// whatever the window count and the key step: a plain split of frames 0-23 in three at key step
// 16 (keys 0, 16, 23) left 8-15 without one, and that window's rad-global refused to run.
TEST(GlobalStage, KeyWindowsTileTheFramesAndEachHoldsAKey) {
  for (const FrameRange frames : {FrameRange{0, 23}, FrameRange{5, 100}, FrameRange{7, 7}})
    for (int step : {1, 4, 8, 16, 48})
      for (int count : {1, 2, 3, 5, 64}) {
        const std::vector<FrameRange> w = keyWindows(frames, step, count);
        const std::vector<int> keys = keyFrames(frames.first, frames.last, step);
        ASSERT_FALSE(w.empty());
        EXPECT_EQ(w.size(), std::min(size_t(count), keys.size()));
        EXPECT_EQ(w.front().first, frames.first);
        EXPECT_EQ(w.back().last, frames.last);
        size_t held = 0;
        for (size_t i = 0; i < w.size(); ++i) {
          if (i > 0) {
            EXPECT_EQ(w[i].first, w[i - 1].last + 1);
          }
          const KeyIndexRange r = windowKeys(frames, step, w[i].toString());  // throws if none
          held += r.last - r.first + 1;
        }
        EXPECT_EQ(held, keys.size());
      }
  EXPECT_EQ(keyWindows({0, 23}, 16, 3).at(1).toString(), "16-22");
}

TEST(GlobalStage, MergeRunRecordsTheWholeRunsCommandLine) {
  auto without = [](std::vector<const char*> argv, std::vector<std::string> merged) {
    return argumentsWithoutMerge(int(argv.size()), argv.data(), merged);
  };
  const std::vector<std::string> whole = {"rad-global", "s.gltf", "-o", "g.rlh", "--eps", "1e-3"};
  EXPECT_EQ(
      without({"rad-global", "s.gltf", "-o", "g.rlh", "--merge", "a.rkw", "b.rkw", "--eps", "1e-3"},
              {"a.rkw", "b.rkw"}),
      whole);
  EXPECT_EQ(without({"rad-global", "s.gltf", "--merge=a.rkw", "-o", "g.rlh", "--merge", "b.rkw",
                     "--eps", "1e-3"},
                    {"a.rkw", "b.rkw"}),
            whole);
  // A word that is not one of the merged files stays (the scene after --merge's values).
  EXPECT_EQ(without({"rad-global", "--merge", "a.rkw", "s.gltf"}, {"a.rkw"}),
            (std::vector<std::string>{"rad-global", "s.gltf"}));
}

}  // namespace
}  // namespace rad
