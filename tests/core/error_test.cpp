#include "core/error.h"

#include <gtest/gtest.h>

namespace throng {

TEST(Error, FileLineColumn) {
  Error e("expected 'OFFSET', found 'OFSET'", at_line("walk.bvh", 212, 3));
  EXPECT_STREQ(e.what(), "walk.bvh:212:3: expected 'OFFSET', found 'OFSET'");
  EXPECT_EQ(e.message(), "expected 'OFFSET', found 'OFSET'");
  EXPECT_EQ(e.location().line, 212);
}

TEST(Error, FieldPath) {
  Error e("must be positive", at_field("groups[2].speed", "scene.yaml"));
  EXPECT_STREQ(e.what(), "scene.yaml: groups[2].speed: must be positive");
  Error bare("must be positive", at_field("dt"));
  EXPECT_STREQ(bare.what(), "dt: must be positive");
}

TEST(Error, LineWithoutFile) {
  EXPECT_STREQ(Error("bad", at_line("", 7)).what(), "line 7: bad");
  EXPECT_STREQ(Error("plain").what(), "plain");
}

}  // namespace throng
