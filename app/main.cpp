// accelviz: entry point. Parses the command line and dispatches to one
// subcommand per cmd_*.cpp. Every failure ends here as one line on stderr:
// exit 1 for a runtime problem (bad file, failed build), 2 for a usage error.
#include "app/cli_common.h"
#include "core/scene/load.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <new>
#include <string>
#include <vector>

namespace {

/// Error messages stay on one line whatever the thrower put in them.
std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

std::string builtin_list() {
  std::string s = "Built-in scenes (SCENE = builtin:NAME[?key=value&...]):\n";
  for (const accelviz::BuiltinSceneInfo& b : accelviz::builtin_scenes())
    s += "  " + b.name + ": " + b.description + (b.parameters.empty() ? "" : " [" + b.parameters + "]") + "\n";
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace accelviz;
  CLI::App app{
      "accelviz: a lab for ray-tracing acceleration structures.\n"
      "Without a subcommand it renders the demo scene's heatmap to a PNG in the current directory."};
  app.set_version_flag("--version", "accelviz 0.1.0");
  app.require_subcommand(0, 1);
  app.footer("\nSCENE is a .gltf/.glb/.obj file or builtin:NAME[?key=value&...].\n" + builtin_list() +
             "Exit codes: 0 success, 1 error (bad file, failed build...), 2 usage error.\n"
             "Documentation: docs/cli.md");

  cli::GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "No progress messages on stderr");

  std::vector<cli::Command> commands = {
      cli::add_info_command(app, global),  cli::add_render_command(app, global), cli::add_bench_command(app, global),
      cli::add_trace_command(app, global), cli::add_rays_command(app, global),
  };
  for (cli::CommandFactory factory : cli::registered_commands()) commands.push_back(factory(app, global));

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every real parse error is a usage error (2).
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  try {
    for (const cli::Command& c : commands)
      if (c.app->parsed()) return c.run();
    return cli::run_demo(global);
  } catch (const cli::UsageError& e) {
    std::fprintf(stderr, "accelviz: %s\n", one_line(e.what()).c_str());
    return 2;
  } catch (const BuildCancelled&) {
    std::fprintf(stderr, "accelviz: cancelled\n");
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "accelviz: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "accelviz: %s\n", one_line(e.what()).c_str());
    return 1;
  }
}
