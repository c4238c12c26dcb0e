// The scratch file behind FormFactorSpill (formats/form_factor_scratch_file.h): sets read back
// bit for bit at the offsets put() gave; what cannot be read is reported, not invented.
#include "formats/form_factor_scratch_file.h"

#include <gtest/gtest.h>

namespace rad {
namespace {

TEST(FormFactorScratchFile, SetsComeBackBitForBit) {
  FormFactorScratchFile file;
  std::vector<double> a = {0.0, 1e-300, 0.125, 3.0}, b = {-2.5, 7.0};
  long long at = file.put(a), bt = file.put(b);
  ASSERT_EQ(at, 0);
  ASSERT_EQ(bt, (long long)(a.size() * sizeof(double)));
  std::vector<double> ra(a.size()), rb(b.size());
  ASSERT_TRUE(file.get(bt, rb));
  ASSERT_TRUE(file.get(at, ra));
  EXPECT_EQ(ra, a);
  EXPECT_EQ(rb, b);
}

TEST(FormFactorScratchFile, WhatWasNotStoredIsNotRead) {
  FormFactorScratchFile file;
  std::vector<double> f(4);
  EXPECT_FALSE(file.get(0, f)) << "nothing stored yet";
  ASSERT_EQ(file.put({1.0, 2.0}), 0);
  EXPECT_FALSE(file.get(-1, f)) << "a set that could not be stored";
  EXPECT_FALSE(file.get(16, f)) << "past the end";
  NoFormFactorSpill none;
  EXPECT_EQ(none.put({1.0}), -1);
  EXPECT_FALSE(none.get(0, f));
}

TEST(FormFactorScratchFile, EachFactoryCallIsItsOwnFile) {
  FormFactorSpillFactory make = formFactorScratchFiles();
  std::unique_ptr<FormFactorSpill> one = make(), two = make();
  EXPECT_EQ(one->put({1.0}), 0);
  EXPECT_EQ(two->put({2.0}), 0);
  std::vector<double> f(1);
  ASSERT_TRUE(two->get(0, f));
  EXPECT_EQ(f[0], 2.0);
}

}  // namespace
}  // namespace rad
