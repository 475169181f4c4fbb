// docs/gui.md documents what the code defines: every shortcut of the Help
// panel (ui/app/shortcuts.h), every option key and every script command.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "ui/app/app_config.h"
#include "ui/app/script.h"
#include "ui/app/shortcuts.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_docs {

using namespace accelviz;

namespace {

std::string gui_docs() {
  std::ifstream in(std::string(ACCELVIZ_SOURCE_DIR) + "/docs/gui.md");
  EXPECT_TRUE(in) << "docs/gui.md missing";
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

TEST(AppShortcuts, DocsListEveryShortcut) {
  const std::string docs = gui_docs();
  for (const Shortcut& s : shortcuts()) {
    EXPECT_NE(docs.find("| " + std::string(s.keys) + " |"), std::string::npos)
        << "docs/gui.md has no table row for '" << s.keys << "'";
    EXPECT_FALSE(s.action.empty());
  }
}

TEST(AppDocs, EveryOptionKeyAndDefaultIsDocumented) {
  const std::string all = gui_docs();
  const auto section = all.find("### Options");
  ASSERT_NE(section, std::string::npos) << "docs/gui.md has no Options section";
  const std::string docs = all.substr(section);
  const AppConfig defaults;
  for (const OptionInfo& o : option_table()) {
    const std::string row = "| `" + std::string(o.key) + "` |";
    const auto at = docs.find(row);
    ASSERT_NE(at, std::string::npos) << "docs/gui.md has no row for option " << o.key;
    const std::string line = docs.substr(at, docs.find('\n', at) - at);
    EXPECT_NE(line.find("| `" + option_value(defaults, o.key) + "` |"), std::string::npos)
        << "the documented default of " << o.key << " is not " << option_value(defaults, o.key) << ": " << line;
    // The values column is the text `set` and its errors give (a '|' escaped for the table).
    std::string values;
    for (const char ch : o.values) values += ch == '|' ? std::string("\\|") : std::string(1, ch);
    EXPECT_EQ(line.rfind(row + " " + values + " | `", 0), 0u)
        << "the documented values of " << o.key << " are not '" << values << "': " << line;
  }
}

TEST(AppDocs, EveryScriptCommandIsDocumented) {
  const std::string docs = gui_docs();
  const std::vector<std::string_view> names = script_command_names();
  EXPECT_GE(names.size(), 26u);
  for (const std::string_view name : names) {
    // A row starts with the command, alone or followed by its arguments.
    const std::string row = "| `" + std::string(name);
    bool found = false;
    for (auto at = docs.find(row); at != std::string::npos && !found; at = docs.find(row, at + 1)) {
      const char next = docs[at + row.size()];
      found = next == '`' || next == ' ';
    }
    EXPECT_TRUE(found) << "docs/gui.md has no row for script command " << name;
  }
}
}  // namespace unity_test_app_docs
