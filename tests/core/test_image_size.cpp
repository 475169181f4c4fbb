// parse_image_size: the "WxH" text of --size and accelviz_gpu_bench.
#include <gtest/gtest.h>

#include "core/util/image_size.h"

namespace accelviz {
namespace {

TEST(ImageSize, ParsesWidthByHeightEitherCase) {
  const auto a = parse_image_size("800x600");
  ASSERT_TRUE(a.has_value());
  EXPECT_EQ(a->width, 800);
  EXPECT_EQ(a->height, 600);
  const auto b = parse_image_size("1X16384");
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->width, 1);
  EXPECT_EQ(b->height, kMaxImageSide);
}

TEST(ImageSize, RejectsEverythingElse) {
  for (const char* text : {"", "x", "800", "800x", "x600", "0x600", "800x0", "-1x5", "+1x5", "16385x1", "1x16385",
                           " 800x600", "800x600 ", "800 x600", "800x600x2", "8.5x6", "99999999999x1", "800*600"})
    EXPECT_FALSE(parse_image_size(text).has_value()) << '"' << text << '"';
}

}  // namespace
}  // namespace accelviz
