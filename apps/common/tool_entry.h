// The entry point of a tool whose work lives in a plugin (apps/CMakeLists.txt, pnpba_tool): the
// tool's executable (tool_launcher.cpp) links no OpenCV, Ceres or BLAS, prints the help the
// build kept, and opens the plugin and calls this for anything else.
#pragma once

#define PNPBA_TOOL_MAIN extern "C" __attribute__((visibility("default"))) int pnpba_tool_main
