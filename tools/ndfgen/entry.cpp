// SPDX-License-Identifier: Apache-2.0
// The ndfgen program: its body is cli::ndfgenMain (main.cpp), which the Python module also runs.
#include <glintbake/cli/embed.h>

int main(int argc, char** argv) { return glintbake::cli::ndfgenMain(argc, argv); }
