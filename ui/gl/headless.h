#pragma once
// The headless context of `accelviz render --device gpu` (and of tests that
// pick one by name): OSMesa (llvmpipe, always there) or EGL on a device (a
// GPU where the machine has one).
#include <memory>
#include <string_view>

#include "ui/gl/context.h"

namespace accelviz {

/// The names make_headless_context takes, as its error message lists them
/// (the CLI's `--gl` choices are the same three, also in builds without ui/).
inline constexpr std::string_view kHeadlessContextNames = "auto, egl or osmesa";

/// `which`: "osmesa" (OSMesa, llvmpipe), "egl" (EGL on a device: a GPU if
/// there is one, else Mesa's software device) or "auto" (EGL on a GPU when
/// there is one, else OSMesa). Makes the context current. Throws GlError
/// when the context cannot be created (the message names the reason), or
/// std::invalid_argument for another name.
std::unique_ptr<GlContext> make_headless_context(int width, int height, std::string_view which);

}  // namespace accelviz
