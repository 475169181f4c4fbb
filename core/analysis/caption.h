#pragma once
// A caption strip under a picture: what it shows, in words, on the picture
// itself (GUI screenshots, `accelviz render`), so that a figure pasted into a
// lecture or a bug report still says what it is.
#include <string>
#include <vector>

#include "core/analysis/heatmap.h"

namespace accelviz {

/// At most this many caption lines under a picture.
inline constexpr int kCaptionMaxLines = 4;

/// `text` in lines of at most `max_chars`, each broken after its last space
/// that fits (mid-word only when none does), at most `max_lines` of them:
/// the last one cut with ".." when the text goes on.
std::vector<std::string> wrap_caption(const std::string& text, int max_chars, int max_lines);

/// The frame with a caption strip below it (a screenshot's
/// screenshot_caption, `accelviz render`'s command line), in the 5×7 font of
/// the legends, wrapped to the width in up to kCaptionMaxLines lines
/// (wrap_caption).
RgbImage add_caption(const RgbImage& frame, const std::string& caption);

}  // namespace accelviz
