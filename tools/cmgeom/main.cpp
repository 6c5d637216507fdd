// cmgeom: the command-line face of CMGeom. Every sub-command lives in its own cmd_<name>.cpp
// and registers itself (see cli_common.h), so adding one never touches this file.
//
// Errors: a sub-command throws; the message is printed on stderr as one line, prefixed with
// "cmgeom <sub-command>: error: ", and the exit code is 1 (2 for command-line usage errors).
#include "cli_common.h"

// every large block of the tool on transparent huge pages (see the header; once per program)
#include <CMGeom/huge_page_new.h>

#include <string>
#include <vector>

int main(int argc, char** argv) { return cmgeom_cli::run(std::vector<std::string>(argv + 1, argv + argc)); }
