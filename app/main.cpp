// accelviz: entry point. Dispatches to one subcommand per cmd_*.cpp.
#include <CLI/CLI.hpp>

#include <cstdio>

int main(int argc, char** argv) {
  CLI::App app{"accelviz: a lab for ray-tracing acceleration structures"};
  app.set_version_flag("--version", "accelviz 0.1.0");
  CLI11_PARSE(app, argc, argv);
  std::puts(app.help().c_str());
  return 0;
}
