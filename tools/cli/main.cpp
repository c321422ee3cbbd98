// kdm: the command line. See `kdm --help` and README.md.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

#include "commands.h"
#include "kdm/runtime/version.h"

int main(int argc, char** argv) {
  CLI::App app{"kdm — blue-noise point sets from Fattal's kernel density model (KDM, SIGGRAPH 2011)"};
  app.set_version_flag("--version", std::string("kdm ") + kdm::version_string() + " (tile-set format " +
                                        std::to_string(kdm::kTilesetFormatVersion) + ")");
  app.require_subcommand(1);
  kdm::cli::add_sample_command(app);
  kdm::cli::add_stipple_command(app);
  kdm::cli::add_query_command(app);
  kdm::cli::add_tile_commands(app);
#ifdef KDM_HAVE_ANALYZE
  kdm::cli::add_analyze_command(app);
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const kdm::cli::CommandError& e) {
    std::fprintf(stderr, "kdm: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kdm: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
