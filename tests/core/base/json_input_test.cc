#include "core/base/json_input.h"
#include "tests/core/test_support.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace armfault {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::HasSubstr;
using testing::Not;
using testing::StartsWith;

using testing_support::ErrorOf;

std::string Nested(int depth) { return std::string(depth, '[') + std::string(depth, ']'); }

// ---------------------------------------------------------------- InputError

TEST(JsonInputError, WhatJoinsSourcePointerAndMessage) {
  const InputError e("run.json", "/joints/3", "bad value");
  EXPECT_EQ(e.source(), "run.json");
  EXPECT_EQ(e.pointer(), "/joints/3");
  EXPECT_EQ(e.message(), "bad value");
  EXPECT_STREQ(e.what(), "run.json: /joints/3: bad value");
}

TEST(JsonInputError, EmptyPointerIsTheDocumentRootAndEmptySourceIsLeftOut) {
  EXPECT_STREQ(InputError("run.json", "", "broken").what(), "run.json: (document root): broken");
  EXPECT_STREQ(InputError("", "/a", "broken").what(), "/a: broken");
}

TEST(JsonInputError, WithSourceKeepsPointerAndMessage) {
  const InputError e = InputError("", "/duration_s", "too long").WithSource("run.json");
  EXPECT_EQ(e.source(), "run.json");
  EXPECT_EQ(e.pointer(), "/duration_s");
  EXPECT_EQ(e.message(), "too long");
  EXPECT_STREQ(e.what(), "run.json: /duration_s: too long");
}

// ---------------------------------------------------------------- ErrorList

TEST(JsonInputErrorList, TryRecordsEachPartsErrorAndGoesOn) {
  ErrorList errors;
  EXPECT_TRUE(errors.Try([] {}));
  EXPECT_FALSE(errors.Try([] { throw InputError("", "/a", "bad a"); }));
  EXPECT_FALSE(errors.Try([] { throw InputError("", "/b", "bad b"); }));
  ASSERT_EQ(errors.size(), 2u);
  const InputError e = ErrorOf([&] { errors.ThrowIfAny(); });
  // It reads as the first error, so code that knows only one error sees what it saw before.
  EXPECT_EQ(e.pointer(), "/a");
  EXPECT_STREQ(e.what(), "/a: bad a");
  ASSERT_EQ(e.count(), 2u);
  EXPECT_EQ(e.errors()[1].pointer(), "/b");
}

TEST(JsonInputErrorList, NothingCollectedThrowsNothing) {
  ErrorList errors;
  EXPECT_NO_THROW(errors.ThrowIfAny());
  EXPECT_TRUE(errors.empty());
}

TEST(JsonInputErrorList, NestedListsFlattenAndRepeatsAreDropped) {
  ErrorList inner;
  inner.Add(InputError("", "/x", "bad"));
  inner.Add(InputError("", "/y", "bad"));
  ErrorList outer;
  outer.Try([&] { inner.ThrowIfAny(); });
  outer.Add(InputError("", "/x", "bad"));    // the same error found by a second check
  outer.Add(InputError("f", "/x", "bad"));   // another file: another error
  ASSERT_EQ(outer.size(), 3u);
  EXPECT_EQ(outer.errors()[0].count(), 1u);
  EXPECT_EQ(outer.errors()[2].source(), "f");
}

TEST(JsonInputErrorList, OtherExceptionsPassThrough) {
  ErrorList errors;
  EXPECT_THROW(errors.Try([] { throw std::logic_error("bug"); }), std::logic_error);
  EXPECT_TRUE(errors.empty());
}

TEST(JsonInputError, WithSourceFillsOnlyTheErrorsThatNameNoFile) {
  const InputError both({InputError("", "/a", "bad"), InputError("monitor.json", "/b", "bad")});
  const std::vector<InputError> e = both.WithSource("camp.json").errors();
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].source(), "camp.json");
  EXPECT_EQ(e[1].source(), "monitor.json");
}

TEST(JsonInputError, EditedRewritesEveryErrorAndKeepsHints) {
  const InputError both({InputError("", "/a", "one", "did you mean \"b\"?"), InputError("", "/c", "two")});
  const InputError edited =
      both.Edited([](std::string*, std::string* pointer, std::string* message) {
        *pointer = "/faults/0" + *pointer;
        *message = "kt_degradation: " + *message;
      });
  const std::vector<InputError> e = edited.errors();
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].pointer(), "/faults/0/a");
  EXPECT_EQ(e[0].message(), "kt_degradation: one");
  EXPECT_EQ(e[0].hint(), "did you mean \"b\"?");
  EXPECT_EQ(e[1].message(), "kt_degradation: two");
}

TEST(JsonInputError, TheHintFollowsTheMessageOnlyInText) {
  const InputError e("run.json", "/duraton_s", "unknown key \"duraton_s\"", "did you mean \"duration_s\"?");
  EXPECT_STREQ(e.what(), "run.json: /duraton_s: unknown key \"duraton_s\"");
  EXPECT_EQ(e.text(), "run.json: /duraton_s: unknown key \"duraton_s\"; did you mean \"duration_s\"?");
  EXPECT_EQ(InputError("run.json", "/a", "bad").text(), "run.json: /a: bad");
}

TEST(JsonInputErrorReport, OneLinePerErrorUpToTheLimitThenHowManyMore) {
  EXPECT_EQ(ErrorReportLines(InputError("c.json", "/a", "bad")), std::vector<std::string>{"c.json: /a: bad"});
  std::vector<InputError> many;
  for (int i = 0; i < 25; ++i) many.emplace_back("c.json", "/v/" + std::to_string(i), "bad");
  const std::vector<std::string> lines = ErrorReportLines(InputError(many));
  ASSERT_EQ(lines.size(), kMaxReportedErrors + 1);
  EXPECT_EQ(lines[0], "c.json: /v/0: bad");
  EXPECT_EQ(lines[19], "c.json: /v/19: bad");
  EXPECT_EQ(lines[20], "... and 5 more errors");
  // Exactly at the limit: no "more" line.
  many.erase(many.begin() + kMaxReportedErrors, many.end());
  EXPECT_EQ(ErrorReportLines(InputError(many)).size(), kMaxReportedErrors);
}

// Errors counted but not kept (a reader of a long file keeps the first ones only) are in the
// "more" line and the count, and survive being collected again or edited.
TEST(JsonInputErrorReport, UnlistedErrorsAreCountedInTheMoreLine) {
  std::vector<InputError> kept;
  for (int i = 0; i < 20; ++i) kept.emplace_back("v.jsonl", "", "line " + std::to_string(i + 1) + ": bad");
  const InputError e(kept, 1000);
  EXPECT_EQ(e.count(), 1020u);
  EXPECT_EQ(e.unlisted(), 1000u);
  EXPECT_EQ(e.errors().size(), 20u);
  std::vector<std::string> lines = ErrorReportLines(e);
  ASSERT_EQ(lines.size(), 21u);
  EXPECT_EQ(lines[19], "v.jsonl: line 20: bad");
  EXPECT_EQ(lines[20], "... and 1000 more errors");
  ErrorList list;
  list.Add(e);
  try {
    list.ThrowIfAny();
    ADD_FAILURE() << "no throw";
  } catch (const InputError& again) {
    EXPECT_EQ(again.count(), 1020u);
  }
  EXPECT_EQ(e.WithSource("x").count(), 1020u);
  // Fewer kept than the limit: the unlisted ones are still said.
  lines = ErrorReportLines(InputError({InputError("v.jsonl", "", "line 1: bad")}, 3));
  EXPECT_EQ(lines, (std::vector<std::string>{"v.jsonl: line 1: bad", "... and 3 more errors"}));
}

TEST(JsonInputDescribe, DumpsShortValuesAndCutsLongOnes) {
  EXPECT_EQ(Describe(json("abc")), "\"abc\"");
  EXPECT_EQ(Describe(json{1, 2}), "[1,2]");
  const std::string long_text = Describe(json(std::string(100, 'x')));
  EXPECT_EQ(long_text, "\"" + std::string(59, 'x') + "...");
}

// ---------------------------------------------------------------- PointerJoin

TEST(JsonInputPointerJoin, EscapesTildeAndSlash) {
  EXPECT_EQ(PointerJoin("", "modules"), "/modules");
  EXPECT_EQ(PointerJoin("/robot", "a/b"), "/robot/a~1b");
  EXPECT_EQ(PointerJoin("/robot", "a~b"), "/robot/a~0b");
  // "~1" literally: the tilde is escaped first, so it does not turn into a slash.
  EXPECT_EQ(PointerJoin("", "~1"), "/~01");
  EXPECT_EQ(PointerJoin("", "~/"), "/~0~1");
  EXPECT_EQ(PointerJoin("", ""), "/");
  EXPECT_EQ(PointerJoin("/links", size_t{2}), "/links/2");
}

TEST(JsonInputPointerJoin, ResultIsAValidJsonPointerToTheKey) {
  const json doc = {{"a/b~c", {{"x", 7}}}};
  const std::string ptr = PointerJoin(PointerJoin("", "a/b~c"), "x");
  EXPECT_EQ(ptr, "/a~1b~0c/x");
  EXPECT_EQ(doc.at(json::json_pointer(ptr)), 7);
}

// ---------------------------------------------------------------- ObjectReader

TEST(JsonInputObjectReader, RejectsNonObjects) {
  const InputError e = ErrorOf([] { ObjectReader r(json::array({1, 2}), "/robot"); });
  EXPECT_EQ(e.source(), "");
  EXPECT_EQ(e.pointer(), "/robot");
  EXPECT_EQ(e.message(), "expected an object, got array [1,2]");
  EXPECT_EQ(ErrorOf([] { ObjectReader r(json("x"), ""); }).message(),
            "expected an object, got string \"x\"");
  EXPECT_EQ(ErrorOf([] { ObjectReader r(json(nullptr), "/j"); }).message(),
            "expected an object, got null null");
}

TEST(JsonInputObjectReader, UnknownKeyIsReportedAtItsOwnPointer) {
  const json obj = {{"mass_kg", 1.0}, {"mas_kg", 2.0}};
  ObjectReader reader(obj, "/links/0");
  double mass = 0;
  reader.OptionalNumber("mass_kg", &mass);
  EXPECT_EQ(mass, 1.0);
  const InputError e = ErrorOf([&] { reader.Finish(); });
  EXPECT_EQ(e.pointer(), "/links/0/mas_kg");
  EXPECT_EQ(e.message(), "unknown key \"mas_kg\"");
}

TEST(JsonInputObjectReader, UnknownKeyPointerIsEscaped) {
  const json obj = {{"a/b", 1}};
  ObjectReader reader(obj, "/x");
  const InputError e = ErrorOf([&] { reader.Finish(); });
  EXPECT_EQ(e.pointer(), "/x/a~1b");
  EXPECT_EQ(e.message(), "unknown key \"a/b\"");
}

TEST(JsonInputObjectReader, FinishReportsTheFirstUnreadKeyInDocumentOrder) {
  // nlohmann::json objects iterate in key order.
  const json obj = {{"zeta", 1}, {"beta", 2}, {"alpha", 3}};
  ObjectReader reader(obj, "");
  reader.Find("alpha");
  EXPECT_EQ(ErrorOf([&] { reader.Finish(); }).pointer(), "/beta");
}

TEST(JsonInputObjectReader, FinishReportsEveryUnreadKeyWithTheNearestKnownOne) {
  const json obj = {{"mas_kg", 1}, {"length_m", 2}, {"zzz", 3}, {"radus_m", 4}};
  ObjectReader reader(obj, "/links/0");
  double x = 0;
  reader.OptionalNumber("mass_kg", &x);     // absent, but asked for: a candidate
  reader.OptionalNumber("length_m", &x);
  reader.OptionalNumber("radius_m", &x);
  const std::vector<InputError> e = ErrorOf([&] { reader.Finish(); }).errors();
  ASSERT_EQ(e.size(), 3u);
  EXPECT_EQ(e[0].pointer(), "/links/0/mas_kg");
  EXPECT_EQ(e[0].message(), "unknown key \"mas_kg\"");
  EXPECT_EQ(e[0].hint(), "did you mean \"mass_kg\"?");
  EXPECT_EQ(e[1].pointer(), "/links/0/radus_m");
  EXPECT_EQ(e[1].hint(), "did you mean \"radius_m\"?");
  EXPECT_EQ(e[2].pointer(), "/links/0/zzz");
  EXPECT_EQ(e[2].hint(), "");  // nothing close
}

TEST(JsonInputObjectReader, AllowOnlySuggestsFromItsList) {
  const json obj = {{"duraton_s", 1}, {"sed", 2}};
  ObjectReader reader(obj, "");
  const std::vector<InputError> e = ErrorOf([&] { reader.AllowOnly({"duration_s", "seed", "robot"}); }).errors();
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].text(), "/duraton_s: unknown key \"duraton_s\"; did you mean \"duration_s\"?");
  EXPECT_EQ(e[1].text(), "/sed: unknown key \"sed\"; did you mean \"seed\"?");
}

TEST(JsonInputObjectReader, FinishAcceptsWhenEveryKeyWasRead) {
  const json obj = {{"a", 1}, {"b", "x"}, {"c", true}, {"d", nullptr}};
  ObjectReader reader(obj, "/o");
  int a = 0;
  std::string b;
  bool c = false;
  reader.OptionalInt("a", &a);
  reader.OptionalString("b", &b);
  reader.OptionalBool("c", &c);
  EXPECT_TRUE(reader.Has("d"));
  EXPECT_NE(reader.Find("d"), nullptr);  // Find marks the key as used, whatever its type
  EXPECT_NO_THROW(reader.Finish());
  EXPECT_EQ(a, 1);
  EXPECT_EQ(b, "x");
  EXPECT_TRUE(c);
}

TEST(JsonInputObjectReader, HasDoesNotMarkAKeyAsUsed) {
  const json obj = {{"a", 1}};
  ObjectReader reader(obj, "");
  EXPECT_TRUE(reader.Has("a"));
  EXPECT_FALSE(reader.Has("b"));
  EXPECT_EQ(ErrorOf([&] { reader.Finish(); }).pointer(), "/a");
}

TEST(JsonInputObjectReader, EmptyObjectFinishesCleanly) {
  const json obj = json::object();
  ObjectReader reader(obj, "/o");
  EXPECT_NO_THROW(reader.Finish());
}

TEST(JsonInputObjectReader, OptionalReadsLeaveTheDefaultWhenAbsent) {
  const json obj = json::object();
  ObjectReader reader(obj, "/o");
  double x = 4.5;
  int n = 7;
  bool flag = true;
  std::string s = "keep";
  reader.OptionalNumber("x", &x);
  reader.OptionalInt("n", &n);
  reader.OptionalBool("flag", &flag);
  reader.OptionalString("s", &s);
  EXPECT_EQ(x, 4.5);
  EXPECT_EQ(n, 7);
  EXPECT_TRUE(flag);
  EXPECT_EQ(s, "keep");
  EXPECT_EQ(reader.Find("x"), nullptr);
}

TEST(JsonInputObjectReader, RequiredKeysMissing) {
  const json obj = {{"other", 1}};
  ObjectReader reader(obj, "/joints/3");
  for (const auto& read : std::vector<std::function<void()>>{
           [&] { reader.Require("amplitude_deg"); }, [&] { reader.RequireNumber("amplitude_deg"); },
           [&] { reader.RequireInt("amplitude_deg"); }, [&] { reader.RequireString("amplitude_deg"); }}) {
    const InputError e = ErrorOf(read);
    EXPECT_EQ(e.pointer(), "/joints/3/amplitude_deg");
    EXPECT_EQ(e.message(), "required key is missing");
  }
}

TEST(JsonInputObjectReader, RequiredKeysPresent) {
  const json obj = {{"n", 3}, {"x", -2.5}, {"s", "sine"}, {"raw", {1}}};
  ObjectReader reader(obj, "");
  EXPECT_EQ(reader.RequireInt("n"), 3);
  EXPECT_EQ(reader.RequireNumber("x"), -2.5);
  EXPECT_EQ(reader.RequireString("s"), "sine");
  EXPECT_EQ(reader.Require("raw"), json({1}));
  EXPECT_NO_THROW(reader.Finish());
}

TEST(JsonInputObjectReader, WrongTypesNameTheTypeAndValue) {
  const json obj = {{"num", "12"}, {"int", true}, {"str", 5}, {"flag", 1}, {"arr", {1, 2}}};
  ObjectReader reader(obj, "/o");
  InputError e = ErrorOf([&] { reader.RequireNumber("num"); });
  EXPECT_EQ(e.pointer(), "/o/num");
  EXPECT_EQ(e.message(), "expected a number, got string \"12\"");
  e = ErrorOf([&] { reader.RequireInt("int"); });
  EXPECT_EQ(e.pointer(), "/o/int");
  EXPECT_EQ(e.message(), "expected a number, got boolean true");
  e = ErrorOf([&] { reader.RequireString("str"); });
  EXPECT_EQ(e.pointer(), "/o/str");
  EXPECT_EQ(e.message(), "expected a string, got number 5");
  bool flag = false;
  e = ErrorOf([&] { reader.OptionalBool("flag", &flag); });
  EXPECT_EQ(e.pointer(), "/o/flag");
  EXPECT_EQ(e.message(), "expected true or false, got 1");
  double x = 0;
  e = ErrorOf([&] { reader.OptionalNumber("arr", &x); });
  EXPECT_EQ(e.pointer(), "/o/arr");
  EXPECT_EQ(e.message(), "expected a number, got array [1,2]");
  EXPECT_EQ(x, 0.0);
}

TEST(JsonInputObjectReader, NullIsNotANumber) {
  const json obj = {{"x", nullptr}};
  ObjectReader reader(obj, "");
  EXPECT_EQ(ErrorOf([&] { reader.RequireNumber("x"); }).message(), "expected a number, got null null");
}

TEST(JsonInputObjectReader, WholeNumbers) {
  const json obj = json::parse(R"({"a": 3, "b": 3.0, "c": -2, "d": 3.5, "e": 3e9, "f": 1e-300,
                                   "g": 2000000000, "h": -2000000000})");
  ObjectReader reader(obj, "/o");
  EXPECT_EQ(reader.RequireInt("a"), 3);
  EXPECT_EQ(reader.RequireInt("b"), 3);  // a float with an integral value is a whole number
  EXPECT_EQ(reader.RequireInt("c"), -2);
  InputError e = ErrorOf([&] { reader.RequireInt("d"); });
  EXPECT_EQ(e.pointer(), "/o/d");
  EXPECT_EQ(e.message(), "expected a whole number, got 3.5");
  e = ErrorOf([&] { reader.RequireInt("e"); });
  EXPECT_EQ(e.pointer(), "/o/e");
  EXPECT_THAT(e.message(), StartsWith("expected a whole number, got 3"));
  EXPECT_EQ(ErrorOf([&] { reader.RequireInt("f"); }).pointer(), "/o/f");
  EXPECT_EQ(reader.RequireInt("g"), 2000000000);
  EXPECT_EQ(reader.RequireInt("h"), -2000000000);
}

TEST(JsonInputValues, AsNumberRejectsNonFiniteValues) {
  const InputError e = ErrorOf([] { AsNumber(json(std::numeric_limits<double>::quiet_NaN()), "/x"); });
  EXPECT_EQ(e.pointer(), "/x");
  EXPECT_THAT(e.message(), StartsWith("expected a finite number"));
  EXPECT_EQ(ErrorOf([] { AsNumber(json(std::numeric_limits<double>::infinity()), "/y"); }).pointer(), "/y");
  EXPECT_EQ(AsNumber(json(7u), "/z"), 7.0);  // unsigned integers are numbers too
}

TEST(JsonInputValues, RangeChecks) {
  EXPECT_NO_THROW(RequireAtLeast(0, 0, "/a"));
  InputError e = ErrorOf([] { RequireAtLeast(-0.5, 0, "/a"); });
  EXPECT_EQ(e.pointer(), "/a");
  EXPECT_EQ(e.message(), "-0.5 is below the minimum 0");

  EXPECT_NO_THROW(RequireAbove(1e-12, 0, "/b"));
  e = ErrorOf([] { RequireAbove(0, 0, "/b"); });
  EXPECT_EQ(e.pointer(), "/b");
  EXPECT_EQ(e.message(), "0 must be greater than 0");

  EXPECT_NO_THROW(RequireInRange(-120, -120, 120, "/c"));
  EXPECT_NO_THROW(RequireInRange(120, -120, 120, "/c"));
  e = ErrorOf([] { RequireInRange(120.5, -120, 120, "/c"); });
  EXPECT_EQ(e.pointer(), "/c");
  EXPECT_EQ(e.message(), "120.5 is outside [-120, 120]");
  EXPECT_EQ(ErrorOf([] { RequireInRange(0.001, 0.002, 3600, "/d"); }).message(),
            "0.001 is outside [0.002, 3600]");
  // NaN never passes a range check.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(RequireAtLeast(nan, 0, "/n"), InputError);
  EXPECT_THROW(RequireAbove(nan, 0, "/n"), InputError);
  EXPECT_THROW(RequireInRange(nan, 0, 1, "/n"), InputError);
}

// ---------------------------------------------------------------- ParseJsonText

TEST(JsonInputParse, ParsesValidDocuments) {
  EXPECT_EQ(ParseJsonText(R"({"a": [1, 2.5, "x"]})", "run.json"), json({{"a", {1, 2.5, "x"}}}));
  EXPECT_EQ(ParseJsonText(" \n 42 \n", "run.json"), json(42));
}

TEST(JsonInputParse, EmptyInputNamesTheSource) {
  for (const std::string text : {"", "   ", " \t\r\n\n"}) {
    const InputError e = ErrorOf([&] { ParseJsonText(text, "empty.json"); });
    EXPECT_EQ(e.source(), "empty.json");
    EXPECT_EQ(e.pointer(), "");
    EXPECT_EQ(e.message(), "the input is empty, expected a JSON document");
    EXPECT_STREQ(e.what(), "empty.json: (document root): the input is empty, expected a JSON document");
  }
}

TEST(JsonInputParse, TruncatedJsonNamesTheSource) {
  for (const std::string text : {R"({"robot": "mrr-config1", "joints": {"3": {)", "[1, 2", "{\"a\"", "\"abc"}) {
    const InputError e = ErrorOf([&] { ParseJsonText(text, "cut.json"); });
    EXPECT_EQ(e.source(), "cut.json") << text;
    EXPECT_EQ(e.pointer(), "") << text;
    EXPECT_THAT(e.message(), StartsWith("not valid JSON: ")) << text;
    // The library's "[json.exception.parse_error.101] " prefix is stripped.
    EXPECT_THAT(e.message(), Not(HasSubstr("json.exception"))) << text;
    EXPECT_THAT(e.message(), HasSubstr("line 1")) << text;
  }
}

TEST(JsonInputParse, NotJsonAtAll) {
  for (const std::string text : {"hello world", "robot = mrr-config1\n", "{'a': 1}", "{\"a\": 1,}",
                                 "{\"a\": 1} trailing", "NaN", "\xff\xfe"}) {
    const InputError e = ErrorOf([&] { ParseJsonText(text, "--joint 3"); });
    EXPECT_EQ(e.source(), "--joint 3") << text;
    EXPECT_EQ(e.pointer(), "") << text;
    EXPECT_THAT(e.message(), StartsWith("not valid JSON: ")) << text;
    EXPECT_THAT(e.what(), StartsWith("--joint 3: not valid JSON: ")) << text;  // an option: no document root
  }
}

TEST(JsonInputParse, SyntaxErrorReportsLineAndColumn) {
  const InputError e = ErrorOf([] { ParseJsonText("{\n  \"a\": 1,\n  \"b\": ?\n}", "run.json"); });
  EXPECT_THAT(e.message(), HasSubstr("line 3, column 8"));
}

TEST(JsonInputParse, NestingUpTo64LevelsIsAccepted) {
  EXPECT_NO_THROW(ParseJsonText(Nested(64), "deep.json"));
  std::string objects;
  for (int i = 0; i < 64; ++i) objects += "{\"a\":";
  objects += "1" + std::string(64, '}');
  EXPECT_NO_THROW(ParseJsonText(objects, "deep.json"));
}

TEST(JsonInputParse, ANumberBeyondADoubleNamesItsField) {
  // nlohmann throws out_of_range.406 here, which its callback parser let escape as an abort.
  for (const auto& [text, pointer] : std::vector<std::pair<std::string, std::string>>{
           {R"({"duration_s": 1e999})", "/duration_s"},
           {R"({"a": [1, {"b": -2e400}]})", "/a/1/b"},
           {R"({"a/b": {"c~d": 1e309}})", "/a~1b/c~0d"},
           {"1e999", ""}}) {
    const InputError e = ErrorOf([&] { ParseJsonText(text, "big.json"); });
    EXPECT_EQ(e.source(), "big.json") << text;
    EXPECT_EQ(e.pointer(), pointer) << text;
    EXPECT_THAT(e.message(), HasSubstr("is beyond the range of a double")) << text;
  }
  // The largest doubles and the smallest subnormal are numbers like any other.
  EXPECT_EQ(ParseJsonText("[1.7976931348623157e308, 5e-324]", "x")[1].get<double>(), 5e-324);
}

TEST(JsonInputParse, AKeyGivenTwiceInOneObjectIsAnError) {
  const InputError e = ErrorOf([] { ParseJsonText(R"({"a": {"b": 1, "c": 2, "b": 3}})", "dup.json"); });
  EXPECT_EQ(e.source(), "dup.json");
  EXPECT_EQ(e.pointer(), "/a/b");
  EXPECT_EQ(e.message(), "the key \"b\" is given twice in one object");
  // The same key in two objects is no repeat.
  EXPECT_NO_THROW(ParseJsonText(R"([{"b": 1}, {"b": 2}, {"x": {"b": 3}}])", "ok.json"));
}

TEST(JsonInputParse, TheDocumentIsNlohmannsOwnValueForValue) {
  // Every shipped campaign, and values of every kind, parse to what nlohmann::json::parse gives.
  std::vector<std::string> texts = {
      R"({"i": -3, "u": 18446744073709551615, "f": 0.1, "e": 1e-300, "s": "a\u00e9", "t": true, "n": null,)"
      R"( "o": {}, "a": [], "z": [[1], {"k": [2.5, "x"]}]})"};
  for (const auto& entry : std::filesystem::directory_iterator(ARMFAULT_SOURCE_DIR "/campaigns/files")) {
    if (!entry.is_regular_file() || entry.path().extension() != ".json") continue;  // robots/: URDF files
    texts.push_back(testing_support::ReadAll(entry.path()));
  }
  for (const std::string& text : texts) {
    const json ours = ParseJsonText(text, "x.json");
    const json theirs = json::parse(text);
    EXPECT_EQ(ours, theirs);
    EXPECT_EQ(ours.dump(), theirs.dump());
  }
}

TEST(JsonInputParse, NestingDeeperThan64IsRejected) {
  for (const std::string& text : {Nested(65), Nested(100000), std::string(100000, '[')}) {
    const InputError e = ErrorOf([&] { ParseJsonText(text, "deep.json"); });
    EXPECT_EQ(e.source(), "deep.json");
    EXPECT_EQ(e.pointer(), "");
    EXPECT_EQ(e.message(), "nesting deeper than 64 levels");
  }
  // Mixed objects and arrays count alike.
  std::string mixed;
  for (int i = 0; i < 40; ++i) mixed += "{\"a\":[";
  mixed += "1";
  for (int i = 0; i < 40; ++i) mixed += "]}";
  EXPECT_EQ(ErrorOf([&] { ParseJsonText(mixed, "mixed.json"); }).message(), "nesting deeper than 64 levels");
}

// ---------------------------------------------------------------- files

class JsonInputFile : public testing::Test {
 protected:
  std::string Write(const std::string& name, const std::string& text) { return scratch_.Write(name, text); }
  testing_support::ScratchDir scratch_{"armfault_json_input_test"};
  const fs::path& dir_ = scratch_.path();
};

TEST_F(JsonInputFile, ReadsAValidFile) {
  const std::string path = Write("run.json", R"({"duration_s": 2})");
  EXPECT_EQ(ReadJsonFile(path), json({{"duration_s", 2}}));
  EXPECT_EQ(ReadTextFile(path), R"({"duration_s": 2})");
}

TEST_F(JsonInputFile, MissingFileNamesThePath) {
  const std::string path = (dir_ / "missing.json").string();
  const InputError e = ErrorOf([&] { ReadJsonFile(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_EQ(e.pointer(), "");
  EXPECT_EQ(e.message(), "cannot open the file for reading");
  EXPECT_EQ(ErrorOf([&] { ReadTextFile(path); }).source(), path);
}

TEST_F(JsonInputFile, ParseErrorsNameThePath) {
  const std::string empty = Write("empty.json", "");
  EXPECT_EQ(ErrorOf([&] { ReadJsonFile(empty); }).source(), empty);
  EXPECT_EQ(ErrorOf([&] { ReadJsonFile(empty); }).message(), "the input is empty, expected a JSON document");
  const std::string cut = Write("cut.json", "{\"robot\": ");
  EXPECT_EQ(ErrorOf([&] { ReadJsonFile(cut); }).source(), cut);
  EXPECT_THAT(ErrorOf([&] { ReadJsonFile(cut); }).message(), StartsWith("not valid JSON: "));
}

TEST_F(JsonInputFile, ADirectoryIsNotAJsonFile) {
  const std::string path = dir_.string();
  const InputError e = ErrorOf([&] { ReadJsonFile(path); });
  EXPECT_EQ(e.source(), path);
}

}  // namespace
}  // namespace armfault
