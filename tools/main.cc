#include <CLI/CLI.hpp>

int main(int argc, char** argv) {
  CLI::App app{"cbrdf: a copula-based codec for measured BRDFs"};
  app.set_version_flag("--version", CBRDF_VERSION_STRING);
  CLI11_PARSE(app, argc, argv);
  return 0;
}
