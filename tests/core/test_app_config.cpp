// The app's option table: every option reads back what was set, errors name
// the option and leave the configuration alone, and the structure
// descriptions/captions say what the picture shows.
#include <gtest/gtest.h>

#include <set>

#include "ui/app/app_config.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_config {

using namespace accelviz;

namespace {

// A second valid value for every key, different from its default.
const std::map<std::string, std::string> kOtherValues = {
    {"structure", "kdtree"},
    {"splitter", "exact"},
    {"buckets", "12"},
    {"leaf", "2"},
    {"leaf-cap", "8"},
    {"ctrav", "1.5"},
    {"cisect", "0.25"},
    {"threads", "3"},
    {"epo", "off"},
    {"kd-ctrav", "2"},
    {"kd-cisect", "3"},
    {"kd-max-depth", "20"},
    {"kd-leaf", "4"},
    {"kd-empty-bonus", "0.5"},
    {"kd-perfect-splits", "off"},
    {"kd-mailboxing", "off"},
    {"grid-res", "4,5,6"},
    {"grid-lambda", "2"},
    {"grid-exact", "off"},
    {"grid-mailboxing", "off"},
    {"octree-depth", "6"},
    {"octree-leaf", "3"},
    {"octree-mailboxing", "off"},
    {"octree-cost-termination", "off"},
    {"voxel-level", "5"},
    {"embree-quality", "high"},
    {"embree-robust", "on"},
    {"embree-isa", "sse2"},
    {"triangle-test", "fast"},
    {"ordered", "off"},
    {"back-to-front", "on"},
    {"xray", "on"},
    {"mesh", "off"},
    {"wireframe", "on"},
    {"boxes", "off"},
    {"box-mode", "subtree"},
    {"box-depth", "7"},
    {"box-depth-last", "9"},
    {"box-node", "12"},
    {"box-color", "sah"},
    {"boxes-through-mesh", "on"},
    {"box-level", "blas"},
    {"box-instance", "3"},
    {"instance-colors", "on"},
    {"heatmap", "blend"},
    {"metric", "prims"},
    {"heatmap-gpu", "on"},
    {"heatmap-gpu-ms", "4"},
    {"colormap", "turbo"},
    {"opacity", "0.3"},
    {"scale", "2,40"},
    {"legend", "off"},
    {"ray-path", "off"},
    {"msaa", "1"},
};

}  // namespace

TEST(AppConfig, EveryOptionReadsBackWhatWasSet) {
  for (const OptionInfo& info : option_table()) {
    const std::string key(info.key);
    ASSERT_TRUE(kOtherValues.count(key)) << "no test value for option " << key;
    AppConfig c;
    const std::string before = option_value(c, key);
    EXPECT_EQ(apply_option(c, key, kOtherValues.at(key)), "") << key;
    EXPECT_EQ(option_value(c, key), kOtherValues.at(key)) << key;
    EXPECT_NE(option_value(c, key), before) << key << ": the test value is the default";
  }
  EXPECT_EQ(kOtherValues.size(), option_table().size()) << "test values for options that no longer exist";
}

TEST(AppConfig, KeysAreUniqueAndDefaultsReadBack) {
  std::set<std::string_view> keys;
  const AppConfig defaults;
  for (const OptionInfo& info : option_table()) {
    EXPECT_TRUE(keys.insert(info.key).second) << "duplicate key " << info.key;
    AppConfig c;
    EXPECT_EQ(apply_option(c, info.key, option_value(defaults, info.key)), "") << info.key;
  }
  // Reapplying every value of a changed configuration reproduces it.
  AppConfig changed;
  for (const auto& [k, v] : kOtherValues) ASSERT_EQ(apply_option(changed, k, v), "") << k;
  AppConfig copy;
  for (const auto& [k, v] : option_values(changed)) ASSERT_EQ(apply_option(copy, k, v), "") << k;
  EXPECT_EQ(option_values(copy), option_values(changed));
}

TEST(AppConfig, ErrorsNameTheOptionAndChangeNothing) {
  AppConfig c;
  const auto before = option_values(c);
  struct Bad {
    const char* key;
    const char* value;
  };
  for (const Bad& b :
       {Bad{"buckets", "1"},      Bad{"buckets", "300"},     Bad{"buckets", "16x"},    Bad{"leaf", "0"},
        Bad{"ctrav", "0"},        Bad{"ctrav", "-1"},        Bad{"ctrav", "nan"},      Bad{"cisect", "inf"},
        Bad{"ctrav", "1e-7"},     Bad{"kd-cisect", "2e6"},   Bad{"splitter", "sah"},   Bad{"structure", "octopus"},
        Bad{"grid-res", "1,2"},   Bad{"grid-res", "0,4,4"},  Bad{"grid-res", "a,b,c"}, Bad{"scale", "5,1"},
        Bad{"scale", "x"},        Bad{"opacity", "1.5"},     Bad{"mesh", "maybe"},     Bad{"msaa", "3"},
        Bad{"voxel-level", "11"}, Bad{"octree-depth", "17"}, Bad{"metric", "time"},    Bad{"colormap", "diverging"}}) {
    const std::string e = apply_option(c, b.key, b.value);
    EXPECT_EQ(e.rfind(std::string(b.key) + ": ", 0), 0u) << b.key << "=" << b.value << " gave '" << e << "'";
    EXPECT_NE(e.find(b.value), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  EXPECT_NE(apply_option(c, "bukets", "4").find("unknown option 'bukets'"), std::string::npos);
  EXPECT_EQ(option_values(c), before);
}

TEST(AppConfig, LeafRaisesTheCapAndTheCapCannotGoBelowTheLeaf) {
  AppConfig c;
  ASSERT_EQ(apply_option(c, "leaf", "20"), "");
  EXPECT_EQ(c.structure.options.bvh.max_leaf_size, 20);
  EXPECT_EQ(c.structure.options.bvh.leaf_size_cap, 20);
  EXPECT_NE(apply_option(c, "leaf-cap", "10"), "");
  EXPECT_EQ(apply_option(c, "leaf-cap", "40"), "");
  EXPECT_NO_THROW(validate(c.structure.options.bvh));
}

TEST(AppConfig, LockedScaleAndGridResolution) {
  AppConfig c;
  ASSERT_EQ(apply_option(c, "scale", "0.5,12"), "");
  EXPECT_FALSE(c.view.auto_scale);
  EXPECT_FLOAT_EQ(c.view.scale_min, 0.5f);
  EXPECT_FLOAT_EQ(c.view.scale_max, 12.0f);
  ASSERT_EQ(apply_option(c, "scale", "auto"), "");
  EXPECT_TRUE(c.view.auto_scale);
  ASSERT_EQ(apply_option(c, "grid-res", "8,1,3"), "");
  EXPECT_EQ(c.structure.options.grid.resolution, (std::array<int, 3>{8, 1, 3}));
  ASSERT_EQ(apply_option(c, "grid-res", "0,0,0"), "");
  EXPECT_EQ(c.structure.options.grid.resolution, (std::array<int, 3>{0, 0, 0}));
}

TEST(AppConfig, SameBuildIgnoresQueryAndOtherTypesOptions) {
  StructureChoice a, b;
  EXPECT_TRUE(same_build(a, b));
  b.query.triangle_test = TriangleTest::moller_trumbore;
  b.query.ordered = false;
  b.options.kdtree.max_leaf_size = 9;  // not the BVH's business
  EXPECT_TRUE(same_build(a, b));
  b.options.bvh.buckets = 8;
  EXPECT_FALSE(same_build(a, b));
  StructureChoice k1, k2;
  k1.name = k2.name = "kdtree";
  k2.options.kdtree.max_leaf_size = 9;
  EXPECT_FALSE(same_build(k1, k2));
  k2 = k1;
  k2.name = "grid";
  EXPECT_FALSE(same_build(k1, k2));
  k2 = k1;
  k2.options.threads = 1;
  EXPECT_FALSE(same_build(k1, k2)) << "the thread count changes what the build reports";
  // tlas builds its levels with the BVH's options: changing one rebuilds it
  // (it did not: the GUI kept the old two-level structure), and its
  // description and screenshots name them.
  StructureChoice t1, t2;
  t1.name = t2.name = "tlas";
  EXPECT_TRUE(same_build(t1, t2));
  t2.options.bvh.buckets = 2;
  EXPECT_FALSE(same_build(t1, t2));
  t2 = t1;
  t2.options.bvh.max_leaf_size = 16;
  EXPECT_FALSE(same_build(t1, t2));
  EXPECT_EQ(describe_structure(t1), "tlas (splitter=binned, buckets=32, leaf=4, leaf-cap=16, ctrav=1, cisect=1)");
}

TEST(AppConfig, DescriptionsAndCaption) {
  AppConfig c;
  EXPECT_EQ(describe_structure(c.structure),
            "bvh (splitter=binned, buckets=32, leaf=4, leaf-cap=16, ctrav=1, cisect=1)");
  c.structure.name = "brute";
  EXPECT_EQ(describe_structure(c.structure), "brute");
  c.structure.name = "grid";
  EXPECT_EQ(describe_structure(c.structure), "grid (grid-res=0,0,0, grid-lambda=3, grid-exact=on, grid-mailboxing=on)");
  ASSERT_EQ(apply_option(c, "heatmap", "blend"), "");
  ASSERT_EQ(apply_option(c, "metric", "cost"), "");
  ASSERT_EQ(apply_option(c, "colormap", "inferno"), "");
  ASSERT_EQ(apply_option(c, "scale", "0,50"), "");
  ASSERT_EQ(apply_option(c, "ordered", "off"), "");
  const std::string cap = screenshot_caption(c);
  for (const char* part : {"grid (", "watertight", "unordered", "heatmap cost inferno scale 0,50", "blend 0.6"})
    EXPECT_NE(cap.find(part), std::string::npos) << part << " missing from: " << cap;
  // The shaded metric is grey shading: no colour map or scale to name.
  ASSERT_EQ(apply_option(c, "metric", "shaded"), "");
  EXPECT_NE(screenshot_caption(c).find(", heatmap shaded blend 0.6"), std::string::npos) << screenshot_caption(c);
  EXPECT_EQ(screenshot_caption(c).find("inferno"), std::string::npos) << screenshot_caption(c);
  ASSERT_EQ(apply_option(c, "heatmap", "off"), "");
  EXPECT_EQ(screenshot_caption(c).find("heatmap"), std::string::npos);
}

TEST(AppConfig, NumbersRoundTripShortest) {
  EXPECT_EQ(format_number(1.0), "1");
  EXPECT_EQ(format_number(0.25), "0.25");
  EXPECT_EQ(format_number(1.5e-5), "1.5e-05");
  for (float f : {0.1f, 1.0f / 3.0f, 3.14159265f, 1e-7f, 123456.789f, -2.5f})
    EXPECT_EQ(std::stof(format_number(f)), f) << format_number(f);
}
}  // namespace unity_test_app_config
