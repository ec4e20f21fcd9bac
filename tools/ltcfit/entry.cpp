// SPDX-License-Identifier: Apache-2.0
// The ltcfit program: its body is cli::ltcfitMain (main.cpp), which the Python module also runs.
#include <glintbake/cli/embed.h>

int main(int argc, char** argv) { return glintbake::cli::ltcfitMain(argc, argv); }
