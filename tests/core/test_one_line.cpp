// joined_line (core/util/one_line.h): what reaches the terminal in an error
// is one line of printable text; UTF-8 names stay as they are.
#include <gtest/gtest.h>

#include <string>

#include "core/util/one_line.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace accelviz::unity_test_one_line {
namespace {

TEST(JoinedLine, BreaksBecomeSpacesAndControlBytesQuestionMarks) {
  EXPECT_EQ(joined_line("a\nb\r\nc\td"), "a b  c d");
  EXPECT_EQ(joined_line("bad\x1b[31mname\x7f"), "bad?[31mname?");
}

// A binary file's bytes quoted in a JSON parser's error went to the terminal raw.
TEST(JoinedLine, BytesThatAreNotUtf8AreQuestionMarksAndUtf8IsKept) {
  EXPECT_EQ(joined_line("K\xc3\xbc"
                        "che \xe6\x97\xa5\xe6\x9c\xac \xf0\x9f\x90\x87.glb"),
            "K\xc3\xbc"
            "che \xe6\x97\xa5\xe6\x9c\xac \xf0\x9f\x90\x87.glb");
  EXPECT_EQ(joined_line("got '\xff\xfe{'"), "got '??{'");
  EXPECT_EQ(joined_line("lone \x80 continuation, cut \xe6\x97"), "lone ? continuation, cut ??");
  EXPECT_EQ(joined_line("overlong \xc0\xaf \xe0\x80\xaf, surrogate \xed\xa0\x80, beyond \xf4\x90\x80\x80"),
            "overlong ?? ???, surrogate ???, beyond ????");
}

}  // namespace
}  // namespace accelviz::unity_test_one_line
