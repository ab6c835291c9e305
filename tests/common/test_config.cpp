#include <gtest/gtest.h>

#include <filesystem>

#include "common/config.hpp"
#include "common/error.hpp"

using namespace stentsim;

namespace {
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Config, ReadsTypedValuesWithUnitsAndDefaults) {
  auto top = ConfigMap::from_string("device:\n  length: 9.4 mm\n  rings: 4\n  curved: true\n", "case.yaml");
  auto dev = top.map("device");
  EXPECT_DOUBLE_EQ(dev.quantity("length", units::kLength), 9.4);
  EXPECT_EQ(dev.integer("rings"), 4);
  EXPECT_TRUE(dev.boolean("curved"));
  EXPECT_DOUBLE_EQ(dev.quantity("wall", units::kLength, 0.04), 0.04);
  EXPECT_NO_THROW(dev.finish());
  EXPECT_NO_THROW(top.finish());
}

TEST(Config, UnknownKeyNamesFileLineKeyAndSuggestion) {
  auto top = ConfigMap::from_string("device:\n  length: 9.4 mm\n  lenght: 3 mm\n", "case.yaml");
  auto dev = top.map("device");
  dev.quantity("length", units::kLength);
  const auto msg = error_of([&] { dev.finish(); });
  EXPECT_NE(msg.find("case.yaml:3:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("device.lenght"), std::string::npos) << msg;
  EXPECT_NE(msg.find("did you mean 'length'"), std::string::npos) << msg;
}

TEST(Config, WrongTypeMissingAndOutOfRangeAreErrors) {
  auto top = ConfigMap::from_string("rings: four\nlength: -1 mm\nlist: {a: 1}\nkind: hex\n", "c.yaml");
  auto msg = error_of([&] { top.integer("rings"); });
  EXPECT_NE(msg.find("c.yaml:1:8: rings: expected an integer, got 'four'"), std::string::npos) << msg;
  msg = error_of([&] { top.quantity("length", units::kLength, std::nullopt, Range::positive()); });
  EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
  EXPECT_NE(msg.find("> 0"), std::string::npos) << msg;
  msg = error_of([&] { top.number("missing"); });
  EXPECT_NE(msg.find("missing: required number is missing"), std::string::npos) << msg;
  msg = error_of([&] { top.number("list"); });
  EXPECT_NE(msg.find("expected a single value"), std::string::npos) << msg;
  msg = error_of([&] { top.choice("kind", {"tet4", "tet10"}); });
  EXPECT_NE(msg.find("'hex' is not one of: tet4, tet10"), std::string::npos) << msg;
}

TEST(Config, SyntaxErrorNamesTheFile) {
  auto msg = error_of([] { ConfigMap::from_string("a: [1, 2\n", "broken.yaml"); });
  EXPECT_NE(msg.find("broken.yaml:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("YAML syntax error"), std::string::npos) << msg;
  msg = error_of([] { ConfigMap::load("/nonexistent/case.yaml"); });
  EXPECT_NE(msg.find("/nonexistent/case.yaml: file not found"), std::string::npos) << msg;
}

// Control characters from the file never reach the terminal raw; a folder is not a case file.
TEST(Config, ControlCharactersAreEscapedAndFoldersRefused) {
  auto top = ConfigMap::from_string("rings: \"4\\e[2J\"\n\"le\\x01ngth\": 1\n", "c.yaml");
  auto msg = error_of([&] { top.integer("rings"); });
  EXPECT_NE(msg.find("got '4\\x1b[2J'"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\x1b'), std::string::npos) << msg;
  top.integer("missing_ok", 1);
  msg = error_of([&] { top.finish(); });
  EXPECT_NE(msg.find("unknown key 'le\\x01ngth'"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\x01'), std::string::npos) << msg;
  const auto dir = std::filesystem::temp_directory_path() / "stentsim_config_folder.yaml";
  std::filesystem::create_directories(dir);
  msg = error_of([&] { ConfigMap::load(dir); });
  EXPECT_NE(msg.find("not a regular file"), std::string::npos) << msg;
  std::filesystem::remove_all(dir);
}

TEST(Config, DuplicateKeysAreErrors) {
  auto msg = error_of([] { ConfigMap::from_string("scene: patient\nmesh: {size: 1}\nscene: generic-artery\n", "dup.yaml"); });
  EXPECT_NE(msg.find("dup.yaml:3:1: scene: duplicate key 'scene'"), std::string::npos) << msg;
  msg = error_of([] { ConfigMap::from_string("cases:\n  - {id: a, x: 1, x: 2}\n", "dup.yaml"); });
  EXPECT_NE(msg.find("cases[0].x: duplicate key 'x'"), std::string::npos) << msg;
}

// Aliases share nodes: nine levels of ten aliases load at once but are a billion values
// to every walk (the duplicate-key check never returned), and an alias inside its own
// anchor is a cycle (a walk recursed until the stack overflowed). Both are refused.
TEST(Config, AliasBombsAndCyclesAreErrors) {
  std::string bomb = "l0: &l0 [a, a, a, a, a, a, a, a, a, a]\n";
  for (int level = 1; level <= 9; ++level) {
    bomb += "l" + std::to_string(level) + ": &l" + std::to_string(level) + " [";
    for (int k = 0; k < 10; ++k) bomb += (k ? ", *l" : "*l") + std::to_string(level - 1);
    bomb += "]\n";
  }
  auto msg = error_of([&] { ConfigMap::from_string(bomb, "bomb.yaml"); });
  EXPECT_NE(msg.find("bomb.yaml: the YAML holds more than 1000000 values once its aliases"), std::string::npos) << msg;
  msg = error_of([] { ConfigMap::from_string("x: &x [*x]\n", "cycle.yaml"); });
  EXPECT_NE(msg.find("cycle.yaml: the YAML nests deeper than 2000 levels"), std::string::npos) << msg;
  // A few aliases are fine.
  EXPECT_NO_THROW(ConfigMap::from_string("a: &a {x: 1}\nb: *a\n", "ok.yaml"));
}

TEST(Config, PathsAreAbsoluteAndRelativeToTheFile) {
  auto top = ConfigMap::from_string("lumen: lumen.stl\n", "cases/p.yaml");
  const auto p = top.path("lumen");
  EXPECT_TRUE(p.is_absolute());
  EXPECT_EQ(p.filename(), "lumen.stl");
  EXPECT_EQ(p.parent_path().filename(), "cases");
}

TEST(Config, CanonicalTextIgnoresKeyOrder) {
  auto a = YAML::Load("{x: 1, y: {b: 2, a: 3}}");
  auto b = YAML::Load("{y: {a: 3, b: 2}, x: 1}");
  auto c = YAML::Load("{y: {a: 3, b: 4}, x: 1}");
  EXPECT_EQ(canonical_yaml(a), canonical_yaml(b));
  EXPECT_NE(canonical_yaml(a), canonical_yaml(c));
}
