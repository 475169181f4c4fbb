#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/procedural/teapot.h"

#include "core/scene/procedural/common.h"
#include "core/scene/procedural/generators.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <unordered_map>

namespace accelviz::procedural {

namespace {

// ---------------------------------------------------------------------------
// The Utah teapot data set (Martin Newell, University of Utah, 1975; public
// domain). Entered here as data, in the published layout: 32 patches of 16
// 1-based control-point indices, then 306 control points (x, y, z), z up.
// Patch groups: 1-4 rim, 5-12 body, 13-16 handle, 17-20 spout, 21-24 lid
// knob, 25-28 lid, 29-32 bottom. Points 205, 206, 216 and 223 (the +-0.002
// offsets near the knob top) are part of the published list but no patch
// uses them; the knob and bottom patches instead repeat a single point along
// their first row (204 and 270), which makes those rows poles.
// ---------------------------------------------------------------------------
constexpr std::uint16_t kPatches1Based[][16] = {
    // rim
    {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16},
    {4, 17, 18, 19, 8, 20, 21, 22, 12, 23, 24, 25, 16, 26, 27, 28},
    {19, 29, 30, 31, 22, 32, 33, 34, 25, 35, 36, 37, 28, 38, 39, 40},
    {31, 41, 42, 1, 34, 43, 44, 5, 37, 45, 46, 9, 40, 47, 48, 13},
    // upper body
    {13, 14, 15, 16, 49, 50, 51, 52, 53, 54, 55, 56, 57, 58, 59, 60},
    {16, 26, 27, 28, 52, 61, 62, 63, 56, 64, 65, 66, 60, 67, 68, 69},
    {28, 38, 39, 40, 63, 70, 71, 72, 66, 73, 74, 75, 69, 76, 77, 78},
    {40, 47, 48, 13, 72, 79, 80, 49, 75, 81, 82, 53, 78, 83, 84, 57},
    // lower body
    {57, 58, 59, 60, 85, 86, 87, 88, 89, 90, 91, 92, 93, 94, 95, 96},
    {60, 67, 68, 69, 88, 97, 98, 99, 92, 100, 101, 102, 96, 103, 104, 105},
    {69, 76, 77, 78, 99, 106, 107, 108, 102, 109, 110, 111, 105, 112, 113, 114},
    {78, 83, 84, 57, 108, 115, 116, 85, 111, 117, 118, 89, 114, 119, 120, 93},
    // handle
    {121, 122, 123, 124, 125, 126, 127, 128, 129, 130, 131, 132, 133, 134, 135, 136},
    {124, 137, 138, 121, 128, 139, 140, 125, 132, 141, 142, 129, 136, 143, 144, 133},
    {133, 134, 135, 136, 145, 146, 147, 148, 149, 150, 151, 152, 69, 153, 154, 155},
    {136, 143, 144, 133, 148, 156, 157, 145, 152, 158, 159, 149, 155, 160, 161, 69},
    // spout
    {162, 163, 164, 165, 166, 167, 168, 169, 170, 171, 172, 173, 174, 175, 176, 177},
    {165, 178, 179, 162, 169, 180, 181, 166, 173, 182, 183, 170, 177, 184, 185, 174},
    {174, 175, 176, 177, 186, 187, 188, 189, 190, 191, 192, 193, 194, 195, 196, 197},
    {177, 184, 185, 174, 189, 198, 199, 186, 193, 200, 201, 190, 197, 202, 203, 194},
    // lid knob
    {204, 204, 204, 204, 207, 208, 209, 210, 211, 211, 211, 211, 212, 213, 214, 215},
    {204, 204, 204, 204, 210, 217, 218, 219, 211, 211, 211, 211, 215, 220, 221, 222},
    {204, 204, 204, 204, 219, 224, 225, 226, 211, 211, 211, 211, 222, 227, 228, 229},
    {204, 204, 204, 204, 226, 230, 231, 207, 211, 211, 211, 211, 229, 232, 233, 212},
    // lid
    {212, 213, 214, 215, 234, 235, 236, 237, 238, 239, 240, 241, 242, 243, 244, 245},
    {215, 220, 221, 222, 237, 246, 247, 248, 241, 249, 250, 251, 245, 252, 253, 254},
    {222, 227, 228, 229, 248, 255, 256, 257, 251, 258, 259, 260, 254, 261, 262, 263},
    {229, 232, 233, 212, 257, 264, 265, 234, 260, 266, 267, 238, 263, 268, 269, 242},
    // bottom
    {270, 270, 270, 270, 279, 280, 281, 282, 275, 276, 277, 278, 271, 272, 273, 274},
    {270, 270, 270, 270, 282, 289, 290, 291, 278, 286, 287, 288, 274, 283, 284, 285},
    {270, 270, 270, 270, 291, 298, 299, 300, 288, 295, 296, 297, 285, 292, 293, 294},
    {270, 270, 270, 270, 300, 305, 306, 279, 297, 303, 304, 275, 294, 301, 302, 271},
};
static_assert(std::size(kPatches1Based) == kTeapotPatchCount);

constexpr float kPoints[][3] = {
    /*   1 */ {1.4f, 0.0f, 2.4f}, {1.4f, -0.784f, 2.4f}, {0.784f, -1.4f, 2.4f}, {0.0f, -1.4f, 2.4f},
    /*   5 */ {1.3375f, 0.0f, 2.53125f}, {1.3375f, -0.749f, 2.53125f}, {0.749f, -1.3375f, 2.53125f},
    /*   8 */ {0.0f, -1.3375f, 2.53125f}, {1.4375f, 0.0f, 2.53125f}, {1.4375f, -0.805f, 2.53125f},
    /*  11 */ {0.805f, -1.4375f, 2.53125f}, {0.0f, -1.4375f, 2.53125f}, {1.5f, 0.0f, 2.4f},
    /*  14 */ {1.5f, -0.84f, 2.4f}, {0.84f, -1.5f, 2.4f}, {0.0f, -1.5f, 2.4f}, {-0.784f, -1.4f, 2.4f},
    /*  18 */ {-1.4f, -0.784f, 2.4f}, {-1.4f, 0.0f, 2.4f}, {-0.749f, -1.3375f, 2.53125f},
    /*  21 */ {-1.3375f, -0.749f, 2.53125f}, {-1.3375f, 0.0f, 2.53125f}, {-0.805f, -1.4375f, 2.53125f},
    /*  24 */ {-1.4375f, -0.805f, 2.53125f}, {-1.4375f, 0.0f, 2.53125f}, {-0.84f, -1.5f, 2.4f},
    /*  27 */ {-1.5f, -0.84f, 2.4f}, {-1.5f, 0.0f, 2.4f}, {-1.4f, 0.784f, 2.4f}, {-0.784f, 1.4f, 2.4f},
    /*  31 */ {0.0f, 1.4f, 2.4f}, {-1.3375f, 0.749f, 2.53125f}, {-0.749f, 1.3375f, 2.53125f},
    /*  34 */ {0.0f, 1.3375f, 2.53125f}, {-1.4375f, 0.805f, 2.53125f}, {-0.805f, 1.4375f, 2.53125f},
    /*  37 */ {0.0f, 1.4375f, 2.53125f}, {-1.5f, 0.84f, 2.4f}, {-0.84f, 1.5f, 2.4f}, {0.0f, 1.5f, 2.4f},
    /*  41 */ {0.784f, 1.4f, 2.4f}, {1.4f, 0.784f, 2.4f}, {0.749f, 1.3375f, 2.53125f},
    /*  44 */ {1.3375f, 0.749f, 2.53125f}, {0.805f, 1.4375f, 2.53125f}, {1.4375f, 0.805f, 2.53125f},
    /*  47 */ {0.84f, 1.5f, 2.4f}, {1.5f, 0.84f, 2.4f}, {1.75f, 0.0f, 1.875f}, {1.75f, -0.98f, 1.875f},
    /*  51 */ {0.98f, -1.75f, 1.875f}, {0.0f, -1.75f, 1.875f}, {2.0f, 0.0f, 1.35f}, {2.0f, -1.12f, 1.35f},
    /*  55 */ {1.12f, -2.0f, 1.35f}, {0.0f, -2.0f, 1.35f}, {2.0f, 0.0f, 0.9f}, {2.0f, -1.12f, 0.9f},
    /*  59 */ {1.12f, -2.0f, 0.9f}, {0.0f, -2.0f, 0.9f}, {-0.98f, -1.75f, 1.875f}, {-1.75f, -0.98f, 1.875f},
    /*  63 */ {-1.75f, 0.0f, 1.875f}, {-1.12f, -2.0f, 1.35f}, {-2.0f, -1.12f, 1.35f}, {-2.0f, 0.0f, 1.35f},
    /*  67 */ {-1.12f, -2.0f, 0.9f}, {-2.0f, -1.12f, 0.9f}, {-2.0f, 0.0f, 0.9f}, {-1.75f, 0.98f, 1.875f},
    /*  71 */ {-0.98f, 1.75f, 1.875f}, {0.0f, 1.75f, 1.875f}, {-2.0f, 1.12f, 1.35f}, {-1.12f, 2.0f, 1.35f},
    /*  75 */ {0.0f, 2.0f, 1.35f}, {-2.0f, 1.12f, 0.9f}, {-1.12f, 2.0f, 0.9f}, {0.0f, 2.0f, 0.9f},
    /*  79 */ {0.98f, 1.75f, 1.875f}, {1.75f, 0.98f, 1.875f}, {1.12f, 2.0f, 1.35f}, {2.0f, 1.12f, 1.35f},
    /*  83 */ {1.12f, 2.0f, 0.9f}, {2.0f, 1.12f, 0.9f}, {2.0f, 0.0f, 0.45f}, {2.0f, -1.12f, 0.45f},
    /*  87 */ {1.12f, -2.0f, 0.45f}, {0.0f, -2.0f, 0.45f}, {1.5f, 0.0f, 0.225f}, {1.5f, -0.84f, 0.225f},
    /*  91 */ {0.84f, -1.5f, 0.225f}, {0.0f, -1.5f, 0.225f}, {1.5f, 0.0f, 0.15f}, {1.5f, -0.84f, 0.15f},
    /*  95 */ {0.84f, -1.5f, 0.15f}, {0.0f, -1.5f, 0.15f}, {-1.12f, -2.0f, 0.45f}, {-2.0f, -1.12f, 0.45f},
    /*  99 */ {-2.0f, 0.0f, 0.45f}, {-0.84f, -1.5f, 0.225f}, {-1.5f, -0.84f, 0.225f}, {-1.5f, 0.0f, 0.225f},
    /* 103 */ {-0.84f, -1.5f, 0.15f}, {-1.5f, -0.84f, 0.15f}, {-1.5f, 0.0f, 0.15f}, {-2.0f, 1.12f, 0.45f},
    /* 107 */ {-1.12f, 2.0f, 0.45f}, {0.0f, 2.0f, 0.45f}, {-1.5f, 0.84f, 0.225f}, {-0.84f, 1.5f, 0.225f},
    /* 111 */ {0.0f, 1.5f, 0.225f}, {-1.5f, 0.84f, 0.15f}, {-0.84f, 1.5f, 0.15f}, {0.0f, 1.5f, 0.15f},
    /* 115 */ {1.12f, 2.0f, 0.45f}, {2.0f, 1.12f, 0.45f}, {0.84f, 1.5f, 0.225f}, {1.5f, 0.84f, 0.225f},
    /* 119 */ {0.84f, 1.5f, 0.15f}, {1.5f, 0.84f, 0.15f}, {-1.6f, 0.0f, 2.025f}, {-1.6f, -0.3f, 2.025f},
    /* 123 */ {-1.5f, -0.3f, 2.25f}, {-1.5f, 0.0f, 2.25f}, {-2.3f, 0.0f, 2.025f}, {-2.3f, -0.3f, 2.025f},
    /* 127 */ {-2.5f, -0.3f, 2.25f}, {-2.5f, 0.0f, 2.25f}, {-2.7f, 0.0f, 2.025f}, {-2.7f, -0.3f, 2.025f},
    /* 131 */ {-3.0f, -0.3f, 2.25f}, {-3.0f, 0.0f, 2.25f}, {-2.7f, 0.0f, 1.8f}, {-2.7f, -0.3f, 1.8f},
    /* 135 */ {-3.0f, -0.3f, 1.8f}, {-3.0f, 0.0f, 1.8f}, {-1.5f, 0.3f, 2.25f}, {-1.6f, 0.3f, 2.025f},
    /* 139 */ {-2.5f, 0.3f, 2.25f}, {-2.3f, 0.3f, 2.025f}, {-3.0f, 0.3f, 2.25f}, {-2.7f, 0.3f, 2.025f},
    /* 143 */ {-3.0f, 0.3f, 1.8f}, {-2.7f, 0.3f, 1.8f}, {-2.7f, 0.0f, 1.575f}, {-2.7f, -0.3f, 1.575f},
    /* 147 */ {-3.0f, -0.3f, 1.35f}, {-3.0f, 0.0f, 1.35f}, {-2.5f, 0.0f, 1.125f}, {-2.5f, -0.3f, 1.125f},
    /* 151 */ {-2.65f, -0.3f, 0.9375f}, {-2.65f, 0.0f, 0.9375f}, {-2.0f, -0.3f, 0.9f}, {-1.9f, -0.3f, 0.6f},
    /* 155 */ {-1.9f, 0.0f, 0.6f}, {-3.0f, 0.3f, 1.35f}, {-2.7f, 0.3f, 1.575f}, {-2.65f, 0.3f, 0.9375f},
    /* 159 */ {-2.5f, 0.3f, 1.125f}, {-1.9f, 0.3f, 0.6f}, {-2.0f, 0.3f, 0.9f}, {1.7f, 0.0f, 1.425f},
    /* 163 */ {1.7f, -0.66f, 1.425f}, {1.7f, -0.66f, 0.6f}, {1.7f, 0.0f, 0.6f}, {2.6f, 0.0f, 1.425f},
    /* 167 */ {2.6f, -0.66f, 1.425f}, {3.1f, -0.66f, 0.825f}, {3.1f, 0.0f, 0.825f}, {2.3f, 0.0f, 2.1f},
    /* 171 */ {2.3f, -0.25f, 2.1f}, {2.4f, -0.25f, 2.025f}, {2.4f, 0.0f, 2.025f}, {2.7f, 0.0f, 2.4f},
    /* 175 */ {2.7f, -0.25f, 2.4f}, {3.3f, -0.25f, 2.4f}, {3.3f, 0.0f, 2.4f}, {1.7f, 0.66f, 0.6f},
    /* 179 */ {1.7f, 0.66f, 1.425f}, {3.1f, 0.66f, 0.825f}, {2.6f, 0.66f, 1.425f}, {2.4f, 0.25f, 2.025f},
    /* 183 */ {2.3f, 0.25f, 2.1f}, {3.3f, 0.25f, 2.4f}, {2.7f, 0.25f, 2.4f}, {2.8f, 0.0f, 2.475f},
    /* 187 */ {2.8f, -0.25f, 2.475f}, {3.525f, -0.25f, 2.49375f}, {3.525f, 0.0f, 2.49375f},
    /* 190 */ {2.9f, 0.0f, 2.475f}, {2.9f, -0.15f, 2.475f}, {3.45f, -0.15f, 2.5125f}, {3.45f, 0.0f, 2.5125f},
    /* 194 */ {2.8f, 0.0f, 2.4f}, {2.8f, -0.15f, 2.4f}, {3.2f, -0.15f, 2.4f}, {3.2f, 0.0f, 2.4f},
    /* 198 */ {3.525f, 0.25f, 2.49375f}, {2.8f, 0.25f, 2.475f}, {3.45f, 0.15f, 2.5125f}, {2.9f, 0.15f, 2.475f},
    /* 202 */ {3.2f, 0.15f, 2.4f}, {2.8f, 0.15f, 2.4f}, {0.0f, 0.0f, 3.15f}, {0.0f, -0.002f, 3.15f},
    /* 206 */ {0.002f, 0.0f, 3.15f}, {0.8f, 0.0f, 3.15f}, {0.8f, -0.45f, 3.15f}, {0.45f, -0.8f, 3.15f},
    /* 210 */ {0.0f, -0.8f, 3.15f}, {0.0f, 0.0f, 2.85f}, {0.2f, 0.0f, 2.7f}, {0.2f, -0.112f, 2.7f},
    /* 214 */ {0.112f, -0.2f, 2.7f}, {0.0f, -0.2f, 2.7f}, {-0.002f, 0.0f, 3.15f}, {-0.45f, -0.8f, 3.15f},
    /* 218 */ {-0.8f, -0.45f, 3.15f}, {-0.8f, 0.0f, 3.15f}, {-0.112f, -0.2f, 2.7f}, {-0.2f, -0.112f, 2.7f},
    /* 222 */ {-0.2f, 0.0f, 2.7f}, {0.0f, 0.002f, 3.15f}, {-0.8f, 0.45f, 3.15f}, {-0.45f, 0.8f, 3.15f},
    /* 226 */ {0.0f, 0.8f, 3.15f}, {-0.2f, 0.112f, 2.7f}, {-0.112f, 0.2f, 2.7f}, {0.0f, 0.2f, 2.7f},
    /* 230 */ {0.45f, 0.8f, 3.15f}, {0.8f, 0.45f, 3.15f}, {0.112f, 0.2f, 2.7f}, {0.2f, 0.112f, 2.7f},
    /* 234 */ {0.4f, 0.0f, 2.55f}, {0.4f, -0.224f, 2.55f}, {0.224f, -0.4f, 2.55f}, {0.0f, -0.4f, 2.55f},
    /* 238 */ {1.3f, 0.0f, 2.55f}, {1.3f, -0.728f, 2.55f}, {0.728f, -1.3f, 2.55f}, {0.0f, -1.3f, 2.55f},
    /* 242 */ {1.3f, 0.0f, 2.4f}, {1.3f, -0.728f, 2.4f}, {0.728f, -1.3f, 2.4f}, {0.0f, -1.3f, 2.4f},
    /* 246 */ {-0.224f, -0.4f, 2.55f}, {-0.4f, -0.224f, 2.55f}, {-0.4f, 0.0f, 2.55f},
    /* 249 */ {-0.728f, -1.3f, 2.55f}, {-1.3f, -0.728f, 2.55f}, {-1.3f, 0.0f, 2.55f},
    /* 252 */ {-0.728f, -1.3f, 2.4f}, {-1.3f, -0.728f, 2.4f}, {-1.3f, 0.0f, 2.4f}, {-0.4f, 0.224f, 2.55f},
    /* 256 */ {-0.224f, 0.4f, 2.55f}, {0.0f, 0.4f, 2.55f}, {-1.3f, 0.728f, 2.55f}, {-0.728f, 1.3f, 2.55f},
    /* 260 */ {0.0f, 1.3f, 2.55f}, {-1.3f, 0.728f, 2.4f}, {-0.728f, 1.3f, 2.4f}, {0.0f, 1.3f, 2.4f},
    /* 264 */ {0.224f, 0.4f, 2.55f}, {0.4f, 0.224f, 2.55f}, {0.728f, 1.3f, 2.55f}, {1.3f, 0.728f, 2.55f},
    /* 268 */ {0.728f, 1.3f, 2.4f}, {1.3f, 0.728f, 2.4f}, {0.0f, 0.0f, 0.0f}, {1.5f, 0.0f, 0.15f},
    /* 272 */ {1.5f, 0.84f, 0.15f}, {0.84f, 1.5f, 0.15f}, {0.0f, 1.5f, 0.15f}, {1.5f, 0.0f, 0.075f},
    /* 276 */ {1.5f, 0.84f, 0.075f}, {0.84f, 1.5f, 0.075f}, {0.0f, 1.5f, 0.075f}, {1.425f, 0.0f, 0.0f},
    /* 280 */ {1.425f, 0.798f, 0.0f}, {0.798f, 1.425f, 0.0f}, {0.0f, 1.425f, 0.0f}, {-0.84f, 1.5f, 0.15f},
    /* 284 */ {-1.5f, 0.84f, 0.15f}, {-1.5f, 0.0f, 0.15f}, {-0.84f, 1.5f, 0.075f}, {-1.5f, 0.84f, 0.075f},
    /* 288 */ {-1.5f, 0.0f, 0.075f}, {-0.798f, 1.425f, 0.0f}, {-1.425f, 0.798f, 0.0f}, {-1.425f, 0.0f, 0.0f},
    /* 292 */ {-1.5f, -0.84f, 0.15f}, {-0.84f, -1.5f, 0.15f}, {0.0f, -1.5f, 0.15f}, {-1.5f, -0.84f, 0.075f},
    /* 296 */ {-0.84f, -1.5f, 0.075f}, {0.0f, -1.5f, 0.075f}, {-1.425f, -0.798f, 0.0f},
    /* 299 */ {-0.798f, -1.425f, 0.0f}, {0.0f, -1.425f, 0.0f}, {0.84f, -1.5f, 0.15f}, {1.5f, -0.84f, 0.15f},
    /* 303 */ {0.84f, -1.5f, 0.075f}, {1.5f, -0.84f, 0.075f}, {0.798f, -1.425f, 0.0f}, {1.425f, -0.798f, 0.0f},
};
static_assert(std::size(kPoints) == kTeapotControlPointCount, "Newell's data set has 306 control points");

/// Cubic Bernstein weights at t = k/n, computed so that the weights at
/// (n-k)/n are the same four numbers in reverse order, bit for bit: t and
/// s = 1 - t both come from exact integers, and B1/B2 use mirrored products.
struct Bernstein {
  double b[4];
};
Bernstein bernstein(int k, int n) {
  const double t = static_cast<double>(k) / n;
  const double s = static_cast<double>(n - k) / n;
  return {{s * s * s, (3.0 * t) * (s * s), (3.0 * s) * (t * t), t * t * t}};
}

/// Sum of four weighted points, grouped so that reversing both the weights
/// and the points gives the identical result (float addition commutes but
/// does not associate). With it, an edge shared by two patches evaluates to
/// the same bits whichever way each patch parameterises it, and weights
/// (1,0,0,0) return a control point exactly.
glm::dvec3 weighted_sum(const Bernstein& w, const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2,
                        const glm::dvec3& p3) {
  return (w.b[0] * p0 + w.b[3] * p3) + (w.b[1] * p1 + w.b[2] * p2);
}

struct PositionKey {
  std::uint32_t bits[3];
  bool operator==(const PositionKey&) const = default;
};
struct PositionKeyHash {
  std::size_t operator()(const PositionKey& k) const {
    std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a over the three words
    for (std::uint32_t w : k.bits) h = (h ^ w) * 0x100000001b3ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};
PositionKey key_of(const glm::vec3& p) {
  PositionKey k;
  const glm::vec3 q = p + glm::vec3(0.0f);  // -0 + 0 = +0: one key for both zeros
  std::memcpy(k.bits, &q[0], sizeof k.bits);
  return k;
}

}  // namespace

const std::array<glm::vec3, kTeapotControlPointCount>& teapot_control_points() {
  static const std::array<glm::vec3, kTeapotControlPointCount> points = [] {
    std::array<glm::vec3, kTeapotControlPointCount> p{};
    for (int i = 0; i < kTeapotControlPointCount; ++i) p[i] = {kPoints[i][0], kPoints[i][1], kPoints[i][2]};
    return p;
  }();
  return points;
}

const std::array<std::array<std::uint16_t, 16>, kTeapotPatchCount>& teapot_patches() {
  static const std::array<std::array<std::uint16_t, 16>, kTeapotPatchCount> patches = [] {
    std::array<std::array<std::uint16_t, 16>, kTeapotPatchCount> p{};
    for (int i = 0; i < kTeapotPatchCount; ++i)
      for (int k = 0; k < 16; ++k) p[i][k] = static_cast<std::uint16_t>(kPatches1Based[i][k] - 1);
    return p;
  }();
  return patches;
}

std::int64_t teapot_triangle_count(int level) {
  const std::int64_t n = level;
  return 64 * n * n - 8 * n;
}

int teapot_level_for(std::int64_t triangles) {
  // 64 n^2 - 8 n = T  =>  n = (8 + sqrt(64 + 256 T)) / 128; then look at the
  // integers around it for the closest count.
  const double estimate = (8.0 + std::sqrt(64.0 + 256.0 * static_cast<double>(triangles))) / 128.0;
  int best = kTeapotMinLevel;
  std::int64_t best_error = INT64_MAX;
  for (int n = std::max(kTeapotMinLevel, static_cast<int>(estimate) - 1); n <= static_cast<int>(estimate) + 2; ++n) {
    const std::int64_t error = std::llabs(teapot_triangle_count(n) - triangles);
    if (error < best_error) best = n, best_error = error;
  }
  return best;
}

Mesh tessellate_teapot(int level) {
  const int n = std::max(level, kTeapotMinLevel);
  const int side = n + 1;
  const auto& points = teapot_control_points();
  const auto& patches = teapot_patches();

  std::vector<Bernstein> weights(side);
  for (int k = 0; k <= n; ++k) weights[k] = bernstein(k, n);

  Mesh mesh;
  mesh.name = "teapot";
  mesh.positions.reserve(static_cast<std::size_t>(kTeapotPatchCount) * side * side);
  mesh.indices.reserve(static_cast<std::size_t>(teapot_triangle_count(n)));

  // Seam vertices are welded by exact position: the evaluation above makes a
  // shared edge produce identical bits in both patches, and the knob and
  // bottom poles collapse to one vertex each. Interior vertices are unique.
  std::unordered_map<PositionKey, std::uint32_t, PositionKeyHash> seam;
  seam.reserve(static_cast<std::size_t>(kTeapotPatchCount) * 4 * n);
  std::vector<std::uint32_t> grid(static_cast<std::size_t>(side) * side);

  for (const auto& patch : patches) {
    glm::dvec3 cp[4][4];
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) cp[i][j] = glm::dvec3(points[patch[4 * i + j]]);

    for (int i = 0; i <= n; ++i) {
      // Collapse u first: column curves at this u, then the v curve through them.
      const Bernstein& wu = weights[i];
      glm::dvec3 col[4];
      for (int j = 0; j < 4; ++j) col[j] = weighted_sum(wu, cp[0][j], cp[1][j], cp[2][j], cp[3][j]);
      for (int j = 0; j <= n; ++j) {
        const glm::dvec3 p = weighted_sum(weights[j], col[0], col[1], col[2], col[3]);
        // Newell's data are z-up; the scene is y-up: (x, y, z) -> (x, z, -y),
        // a proper rotation of -90 degrees about x.
        const glm::vec3 q(static_cast<float>(p.x), static_cast<float>(p.z), -static_cast<float>(p.y));
        std::uint32_t index = static_cast<std::uint32_t>(mesh.positions.size());
        const bool on_seam = i == 0 || j == 0 || i == n || j == n;
        if (on_seam) {
          const auto [it, inserted] = seam.try_emplace(key_of(q), index);
          if (!inserted) index = it->second;
        }
        if (index == mesh.positions.size()) mesh.positions.push_back(q);
        grid[static_cast<std::size_t>(i) * side + j] = index;
      }
    }

    // Two triangles per grid quad. Newell's patches have du x dv pointing
    // into the pot, so (i,j) -> (i,j+1) -> (i+1,j+1) winds outward. A
    // triangle that repeats a welded vertex has zero area (it lies on a pole
    // row): it is dropped, leaving a clean fan around the pole.
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const std::uint32_t a = grid[static_cast<std::size_t>(i) * side + j];
        const std::uint32_t b = grid[static_cast<std::size_t>(i) * side + j + 1];
        const std::uint32_t c = grid[static_cast<std::size_t>(i + 1) * side + j + 1];
        const std::uint32_t d = grid[static_cast<std::size_t>(i + 1) * side + j];
        if (a != b && b != c && a != c) mesh.indices.emplace_back(a, b, c);
        if (a != c && c != d && a != d) mesh.indices.emplace_back(a, c, d);
      }
    }
  }
  return mesh;
}

// ---------------------------------------------------------------------------
// builtin:teapot — the teapot alone, on no ground, with one camera and a light.
// ---------------------------------------------------------------------------
Scene make_teapot(const BuiltinArgs& args) {
  Scene scene;
  Mesh mesh = tessellate_teapot(teapot_level_for(args.size));
  const Aabb box = mesh_bounds(mesh);
  place_mesh(scene, add_mesh(scene, std::move(mesh)), "teapot");
  // Three-quarter view from the front right, spout to the right.
  scene.cameras.push_back(frame_box("front", box, glm::vec3(0.5f, 0.45f, 1.0f)));
  // Key light above and in front; intensity ~ distance^2 so that the
  // inverse-square irradiance at the teapot is about 1.
  const glm::vec3 light_pos(4.0f, 8.0f, 6.0f);
  const glm::vec3 to_teapot = light_pos - box.center();
  scene.lights.push_back(point_light("key", light_pos, glm::dot(to_teapot, to_teapot)));
  finish(scene, args);
  return scene;
}

}  // namespace accelviz::procedural
