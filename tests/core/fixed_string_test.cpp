#include "core/fixed_string.hpp"

#include <gtest/gtest.h>

using drivegate::core::FixedString;

TEST(FixedString, KeepsShortTextAndMarksTruncation) {
  FixedString<8> s("abc");
  EXPECT_EQ(s.view(), "abc");
  s.assign("0123456789");
  EXPECT_EQ(s.view(), "01234...");
  EXPECT_EQ(s.size(), 8u);
}

TEST(FixedString, DoesNotCutUtf8Sequences) {
  FixedString<8> s;
  s.assign("abcd\xc3\xa4xyzw");  // "abcdäxyzw": 'ä' straddles the cut point
  EXPECT_EQ(s.view(), "abcd...");
}

TEST(FixedString, FormatsAndTruncates) {
  FixedString<16> s;
  s.format("%s=%d", "axis", 42);
  EXPECT_EQ(s.view(), "axis=42");
  s.format("%s", "a very long string indeed");
  EXPECT_EQ(s.size(), 16u);
  EXPECT_EQ(s.view().substr(13), "...");
}

TEST(FixedString, FormattedTruncationKeepsUtf8Whole) {
  FixedString<8> s;
  s.format("%s", "abcd\xc3\xa4xyzw");
  EXPECT_EQ(s.view(), "abcd...");
}
