// The `tessera` command: render, bench (and, with the farm, submit). Logic lives in tessera_cli.
#include "tessera/cli/commands.h"

int main(int argc, char** argv) { return tessera::cli::main_entry(argc, argv); }
