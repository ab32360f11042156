#pragma once
// The cache reader's refusal of a damaged first frame, as the block tests
// expect it: reading frame 0 throws CorruptDataError naming the file, "frame
// 1" and the damaged block, and verifyAll() reports exactly that frame.
#include <gtest/gtest.h>

#include <string>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/error.hpp"

namespace crumple::test {

inline void expectFirstFrameRefused(const std::string& path, const std::string& block) {
  const cache::CacheReader r(path);
  try {
    (void)r.readFrame(0);
    ADD_FAILURE() << "read without an error";
  } catch (const CorruptDataError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path + ": frame 1"), std::string::npos) << what;
    EXPECT_NE(what.find(block), std::string::npos) << what;
  }
  const auto issues = r.verifyAll();
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].frame, 1);
}

}  // namespace crumple::test
