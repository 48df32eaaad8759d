// The plugin loader: a missing plugin and one of another version are clear errors that name
// the file and where it was looked for; a built plugin loads once and gives its functions.
#include "pnpba/core/plugin.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include "pnpba/core/error.h"

namespace pnpba {
namespace {

std::string errorOf(const std::string& plugin, const std::string& symbol) {
  try {
    pluginSymbol(plugin, symbol);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Plugin, MissingPluginNamesTheFileEveryFolderAndTheRemedy) {
  const std::string error = errorOf("no_such_plugin", "f");
  EXPECT_NE(error.find("libpnpba_no_such_plugin.so"), std::string::npos) << error;
  EXPECT_NE(error.find("PNPBA_PLUGIN_DIR"), std::string::npos) << error;
  for (const std::string& dir : pluginSearchPath()) {
    EXPECT_NE(error.find(dir + "/libpnpba_no_such_plugin.so: not found"), std::string::npos)
        << error;
  }
  EXPECT_FALSE(pluginLoaded("no_such_plugin"));
}

TEST(Plugin, PluginOfAnotherVersionIsPassedOverNeverCalled) {
  ::setenv("PNPBA_PLUGIN_DIR", STALE_PLUGIN_DIR, 1);
  const std::string error = errorOf("stale", "pnpba_stale_answer");
  ::unsetenv("PNPBA_PLUGIN_DIR");
  EXPECT_NE(error.find("built for another version of pnpba (pnpba-0.0.0-stale"), std::string::npos)
      << error;
  EXPECT_FALSE(pluginLoaded("stale"));
}

TEST(Plugin, EnvironmentFolderComesFirst) {
  ::setenv("PNPBA_PLUGIN_DIR", "/some/folder", 1);
  const std::vector<std::string> dirs = pluginSearchPath();
  ::unsetenv("PNPBA_PLUGIN_DIR");
  ASSERT_FALSE(dirs.empty());
  EXPECT_EQ(dirs[0], "/some/folder");
}

TEST(Plugin, BuiltPluginLoadsOnceAndGivesItsFunctions) {
  using Abi = const char*();
  Abi* abi = pluginFunction<Abi>("imgcodecs", "pnpba_plugin_abi");
  ASSERT_NE(abi, nullptr);
  EXPECT_TRUE(pluginLoaded("imgcodecs"));
  EXPECT_EQ(pluginFunction<Abi>("imgcodecs", "pnpba_plugin_abi"), abi);
  EXPECT_NE(errorOf("imgcodecs", "no_such_symbol").find("lacks no_such_symbol"), std::string::npos);
}

}  // namespace
}  // namespace pnpba
