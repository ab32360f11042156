// The developer switches (core/debug.hpp): `--debug` parses into one set.
#include <gtest/gtest.h>

#include "crumple/core/debug.hpp"
#include "crumple/core/error.hpp"

namespace crumple {
namespace {

TEST(DebugOptions, ParseEverySwitchAndNothingElse) {
  const DebugOptions none = parseDebugOptions("");
  EXPECT_FALSE(none.newton || none.tear || none.invariants);
  EXPECT_EQ(none.geometry, 0);
  EXPECT_TRUE(none.dump.empty());
  const DebugOptions all = parseDebugOptions("newton,geometry=2,tear,invariants,dump=/tmp/x.obj");
  EXPECT_TRUE(all.newton && all.tear && all.invariants);
  EXPECT_EQ(all.geometry, 2);
  EXPECT_EQ(all.dump, "/tmp/x.obj");
  EXPECT_EQ(parseDebugOptions("geometry").geometry, 1);
  for (const char* bad : {"netwon", "geometry=4", "geometry=", "dump", "dump=", "tear=1", ","})
    EXPECT_THROW((void)parseDebugOptions(bad), InputError) << bad;
  try {
    (void)parseDebugOptions("newton,speed");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown switch 'speed'"), std::string::npos) << e.what();
  }
}

TEST(DebugOptions, TheProcessHoldsOneSet) {
  DebugOptions d;
  d.tear = true;
  setDebugOptions(d);
  EXPECT_TRUE(debugOptions().tear);
  setDebugOptions({});
  EXPECT_FALSE(debugOptions().tear);
}

}  // namespace
}  // namespace crumple
