// Hand-edited JSON files: whatever the bytes, one InputError naming the file, the line or the  // SPDX-License-Identifier: Apache-2.0
// field, never a library exception (a number overflow used to abort the server).
#include "viscera/common/json_input.hpp"

#include <filesystem>
#include <functional>

#include <sys/stat.h>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/material/material_file.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
using namespace viscera::common;
namespace test = viscera::tissue::test;

namespace {
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST(JsonInput, NumberOverflowAndSyntaxErrorsNameTheLine) {
  EXPECT_EQ(error_of([] { parse_json("{\n  \"a\": 1,\n  \"b\": 1e999\n}", "f.json"); }), "f.json:3: JSON: number overflow parsing '1e999'");
  EXPECT_EQ(error_of([] { parse_json("{\n  \"a\": -1e400 }", "f.json"); }), "f.json:2: JSON: number overflow parsing '-1e400'");
  // An integer too long for any integer type is read as a double, and overflows as one.
  EXPECT_NE(error_of([] { parse_json("[" + std::string(400, '9') + "]", "f.json"); }).find("f.json:1: JSON: number overflow"), std::string::npos);
  const std::string syntax = error_of([] { parse_json("{\"a\": 1,\n\n}", "f.json"); });
  EXPECT_EQ(syntax.rfind("f.json:3: JSON: parse error at line 3, column 1: syntax error", 0), 0u) << syntax;
  EXPECT_EQ(error_of([] { parse_json("", "f.json"); }).rfind("f.json:1: JSON:", 0), 0u);
}

TEST(JsonInput, AKeyGivenTwiceIsAnErrorNotTheLastOneSilently) {
  EXPECT_EQ(error_of([] { parse_json(R"({"organ": {"mesh": "a", "mesh": "b"}})", "s.json"); }), "s.json: organ.mesh: given twice (each field once)");
  EXPECT_EQ(error_of([] { parse_json(R"({"i": [{"id": 1}, {"id": 2, "id": 3}]})", "s.json"); }), "s.json: i[1].id: given twice (each field once)");
  EXPECT_EQ(error_of([] { parse_json(R"([{"a": 1}, {"a": 2}])", "s.json"); }), "no error");
}

TEST(JsonInput, NestingIsBoundedSoNoInputCanExhaustTheStack) {
  const auto nested = [](std::size_t depth, char open, char close) { return std::string(depth, open) + std::string(depth, close); };
  // 100,000 levels (a printed message or a dump of it recursed once per level, and crashed).
  for (const auto& [open, close] : {std::pair{'[', ']'}, std::pair{'{', '}'}}) {
    std::string deep = nested(100000, open, close);
    if (open == '{') {  // objects need keys: {"a":{"a":...}}
      deep.clear();
      for (int k = 0; k < 100000; ++k) deep += "{\"a\":";
      deep += "1" + std::string(100000, '}');
    }
    EXPECT_EQ(error_of([&] { parse_json(deep, "deep.json"); }), "deep.json: JSON: objects and arrays nested deeper than 64 levels");
    std::string why;
    EXPECT_FALSE(try_parse_json(deep, &why));
    EXPECT_NE(why.find("nested deeper than 64"), std::string::npos) << why;
  }
  // The bound itself: 64 levels read, 65 do not.
  EXPECT_TRUE(parse_json(nested(kMaxJsonDepth, '[', ']'), "f.json").is_array());
  EXPECT_NE(error_of([&] { parse_json(nested(kMaxJsonDepth + 1, '[', ']'), "f.json"); }).find("nested deeper"), std::string::npos);
  // A deep value where an object is expected is named, not printed whole.
  const nlohmann::json j = parse_json(nested(60, '[', ']'), "f.json");
  EXPECT_NE(error_of([&] { JsonObject(j, "f.json"); }).find("is not an object"), std::string::npos);
}

TEST(JsonInput, TextFieldsHoldNoControlCharactersForTheTerminal) {
  const nlohmann::json j = parse_json(R"({"a": "liver \u00e9", "b": "\u001b]0;owned\u0007", "c": "two\nlines", "d": "c1 \u009b2J"})", "f.json");
  const JsonObject o(j, "f.json");
  EXPECT_EQ(o.text("a"), "liver \xC3\xA9");  // UTF-8 is text
  EXPECT_EQ(error_of([&] { o.text("b"); }),
            "f.json: b: '\\x1B]0;owned\\x07' holds a control character (a newline, an escape): text fields are printed");
  EXPECT_NE(error_of([&] { o.text("c"); }).find("holds a control character"), std::string::npos);
  EXPECT_NE(error_of([&] { o.text("d"); }).find("holds a control character"), std::string::npos);  // a C1 control in UTF-8
}

TEST(JsonInput, AByteOrderMarkIsSkipped) { EXPECT_EQ(parse_json("\xEF\xBB\xBF{\"a\": 2}", "bom.json")["a"].get<int>(), 2); }

TEST(JsonInput, FieldsAreCheckedForTypeRangeAndWholeness) {
  const auto j = parse_json(R"({"x": "3", "y": 1e300, "n": 2.5, "k": [1, "a"], "o": {"z": true}})", "f.json");
  const JsonObject o(j, "f.json");
  EXPECT_EQ(error_of([&] { o.number("x", 0, 10); }), "f.json: x: \"3\" is not a number");
  EXPECT_EQ(error_of([&] { o.number("y", 0, 1e6); }), "f.json: y: 1e+300 is outside [0, 1e+06]");  // printed short
  EXPECT_EQ(error_of([&] { o.integer("n", 0, 10); }), "f.json: n: 2.5 is not a whole number");
  EXPECT_EQ(error_of([&] { o.numbers("k", 2, 0, 9); }), "f.json: k[1]: \"a\" is not a number");
  EXPECT_EQ(error_of([&] { o.number("missing", 0, 1); }), "f.json: missing: missing");
  EXPECT_EQ(o.number("missing", 0, 1, 0.5), 0.5);
  EXPECT_EQ(error_of([&] { o.object("o").number("z", 0, 1); }), "f.json: o.z: true is not a number");
  EXPECT_EQ(error_of([&] { o.require_known({"x", "y", "n", "k"}); }), "f.json: o: unknown field (known here: x, y, n, k)");
  EXPECT_EQ(error_of([&] { o.choice("x", {"a", "b"}, "a"); }), "f.json: x: '3' is not one of a | b");
}

TEST(JsonInput, OnlyRegularFilesOfBoundedSizeAreRead) {
  const std::string fifo = test::tmp_path("fifo.json");
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { read_json_file(fifo); }), fifo + ": is not a regular file (a FIFO, socket or device?)");
  EXPECT_NE(error_of([] { read_json_file(test::tmp_path("")); }).find(": is a directory, not a file"), std::string::npos);
  EXPECT_NE(error_of([] { read_text_file(test::write_file("big.json", std::string(2000, ' ')), 1000); }).find("is 2000 bytes, more than the 1000"),
            std::string::npos);
}

TEST(JsonInput, MaterialFilesSurviveOverflowAndWrongTypes) {
  const std::string head = R"({"density_kg_m3": 1000, "elasticity": {"type": "isotropic", "youngs_modulus_pa": )";
  EXPECT_EQ(error_of([&] { parse_material(head + "1e999, \"poisson_ratio\": 0.3}}", "m.json"); }), "m.json:1: JSON: number overflow parsing '1e999'");
  EXPECT_EQ(error_of([&] { parse_material(head + "1e20, \"poisson_ratio\": 0.3}}", "m.json"); }),
            "m.json: elasticity.youngs_modulus_pa: 1e+20 is outside [0.001, 1e+12]");
  EXPECT_EQ(error_of([] { parse_material(R"({"density_kg_m3": 1000, "elasticity": {"type": 3}})", "m.json"); }),
            "m.json: elasticity.type: 3 is not a string");
  EXPECT_EQ(error_of([] {
              parse_material(R"({"density_kg_m3": 1000, "elasticity": {"type": "transversely_isotropic", "plane_youngs_modulus_pa": 1000,
                 "plane_poisson_ratio": 0.3, "fibre_youngs_modulus_pa": 2000, "fibre_plane_poisson_ratio": 0.3, "fibre_shear_modulus_pa": 500,
                 "fibre_direction": [0, "z", 1]}})",
                             "m.json");
            }),
            "m.json: elasticity.fibre_direction[1]: \"z\" is not a number");
}

TEST(InputError, PrintableNeverPassesControlBytesAndCutsLongText) {
  EXPECT_EQ(printable("a\x1b[2Jb\x80"), "a\\x1B[2Jb\\x80");
  EXPECT_EQ(printable(std::string(100, 'x'), 10), std::string(10, 'x') + "...");
  EXPECT_EQ(short_number(1e300), "1e+300");
  EXPECT_EQ(short_number(0.0123456789), "0.0123457");
}
