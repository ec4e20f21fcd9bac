// SPDX-License-Identifier: Apache-2.0
// The tensorpack program: its body is cli::tensorpackMain (main.cpp), which the Python module also runs.
#include <glintbake/cli/embed.h>

int main(int argc, char** argv) { return glintbake::cli::tensorpackMain(argc, argv); }
