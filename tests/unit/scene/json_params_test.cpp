// The strict JSON reader/writer/doc visitors on small parameter structs.
#include "follicle/scene/json_params.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::scene;
using ::testing::HasSubstr;

namespace {

enum class Mode { Fast, Careful };
constexpr std::array<std::pair<Mode, const char*>, 2> follicle_enum_names(Mode) {
  return {{{Mode::Fast, "fast"}, {Mode::Careful, "careful"}}};
}

struct Inner {
  double stiffness = 2.0;
  Vec3 axis{0, 1, 0};
  template <class V>
  void visit(V&& v) {
    v("stiffness", stiffness, ParamInfo{"bending stiffness", "N m^2", 0.0, 10.0});
    v("axis", axis, ParamInfo{"axis", "", -1.0, 1.0});
  }
};

struct Item {
  static constexpr const char* kRequired[] = {"id"};
  int id = 0;
  std::string label = "x";
  template <class V>
  void visit(V&& v) {
    v("id", id, ParamInfo{"identifier", "", 0, 100});
    v("label", label, ParamInfo{"label"});
  }
};

struct Outer {
  double speed = 5.0;
  int count = 3;
  unsigned seed = 7;
  bool enabled = true;
  std::string name = "gust";
  Mode mode = Mode::Fast;
  LengthUnit units = LengthUnit::mm;
  Inner inner;
  std::vector<Item> items;
  std::vector<double> weights;
  std::map<std::string, Inner> named;
  std::optional<double> maybe;
  template <class V>
  void visit(V&& v) {
    v("speed", speed, ParamInfo{"peak wind speed", "m/s", 0.0, 100.0});
    v("count", count, ParamInfo{"count", "", 1, 1000});
    v("seed", seed, ParamInfo{"seed"});
    v("enabled", enabled, ParamInfo{"on/off"});
    v("name", name, ParamInfo{"name"});
    v("mode", mode, ParamInfo{"mode"});
    v("units", units, ParamInfo{"units"});
    v("inner", inner, ParamInfo{"inner"});
    v("items", items, ParamInfo{"items"});
    v("weights", weights, ParamInfo{"weights", "", 0.0, 1.0});
    v("named", named, ParamInfo{"named"});
    v("maybe", maybe, ParamInfo{"optional", "", 0.0, 1.0});
  }
};

Outer read(const std::string& text) {
  Outer o;
  read_json(parse_json_text(text, "test.json"), "", o, JsonSource{"test.json"});
  return o;
}

std::string error_of(const std::string& text) {
  try {
    read(text);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(JsonReader, ReadsEveryFieldTypeAndKeepsDefaults) {
  const Outer o = read(R"({"speed": 2.5, "count": 4.0, "enabled": false, "mode": "careful",
      "units": "cm", "inner": {"axis": [1, 0, 0]}, "items": [{"id": 3}, {"id": 4, "label": "b"}],
      "weights": [0.25, 0.5], "named": {"a": {"stiffness": 1}}, "maybe": 0.5,
      "// note": "comments are ignored"})");
  EXPECT_EQ(o.speed, 2.5);
  EXPECT_EQ(o.count, 4);
  EXPECT_EQ(o.seed, 7u);  // default kept
  EXPECT_FALSE(o.enabled);
  EXPECT_EQ(o.name, "gust");
  EXPECT_EQ(o.mode, Mode::Careful);
  EXPECT_EQ(o.units, LengthUnit::cm);
  EXPECT_EQ(o.inner.stiffness, 2.0);
  EXPECT_EQ(o.inner.axis, Vec3(1, 0, 0));
  ASSERT_EQ(o.items.size(), 2u);
  EXPECT_EQ(o.items[0].id, 3);
  EXPECT_EQ(o.items[0].label, "x");
  EXPECT_EQ(o.items[1].label, "b");
  EXPECT_EQ(o.weights, (std::vector<double>{0.25, 0.5}));
  ASSERT_EQ(o.named.count("a"), 1u);
  EXPECT_EQ(o.named.at("a").stiffness, 1.0);
  ASSERT_TRUE(o.maybe.has_value());
  EXPECT_EQ(*o.maybe, 0.5);
}

TEST(JsonReader, UnknownKeyNamesFilePathAndSuggestion) {
  const auto e = error_of(R"({"inner": {"stifness": 1}})");
  EXPECT_THAT(e, HasSubstr("test.json"));
  EXPECT_THAT(e, HasSubstr("inner.stifness"));
  EXPECT_THAT(e, HasSubstr("did you mean \"stiffness\"?"));
  EXPECT_THAT(e, HasSubstr("unknown key"));
  // In an array element, the index is part of the path.
  const auto e2 = error_of(R"({"items": [{"id": 1}, {"id": 2, "lable": "q"}]})");
  EXPECT_THAT(e2, HasSubstr("items[1].lable"));
  EXPECT_THAT(e2, HasSubstr("did you mean \"label\"?"));
  // Nothing close: no suggestion, but the accepted keys are listed.
  const auto e3 = error_of(R"({"zzzzzzzz": 1})");
  EXPECT_THAT(e3, ::testing::Not(HasSubstr("did you mean")));
  EXPECT_THAT(e3, HasSubstr("\"speed\""));
}

TEST(JsonReader, WrongTypesSayWhatWasExpected) {
  EXPECT_THAT(error_of(R"({"speed": "fast"})"),
              HasSubstr("speed: expected a number, got a string \"fast\""));
  EXPECT_THAT(error_of(R"({"count": 2.5})"),
              HasSubstr("count: expected an integer, got a number 2.5"));
  EXPECT_THAT(error_of(R"({"enabled": 1})"), HasSubstr("enabled: expected true or false"));
  EXPECT_THAT(error_of(R"({"name": 3})"), HasSubstr("name: expected a string, got a number 3"));
  EXPECT_THAT(error_of(R"({"inner": [1]})"), HasSubstr("inner: expected an object, got an array"));
  EXPECT_THAT(error_of(R"({"inner": {"axis": [1, 2]}})"),
              HasSubstr("inner.axis: expected an array of 3 numbers"));
  EXPECT_THAT(error_of(R"({"inner": {"axis": [0, "a", 0]}})"),
              HasSubstr("inner.axis[1]: expected a number"));
  EXPECT_THAT(error_of(R"({"items": {"id": 1}})"), HasSubstr("items: expected an array"));
  EXPECT_THAT(error_of(R"({"seed": -1})"), HasSubstr("seed: value -1 does not fit"));
  EXPECT_THAT(error_of(R"({"mode": "fsat"})"), HasSubstr("did you mean \"fast\"?"));
  EXPECT_THAT(error_of(R"({"units": "inch"})"), HasSubstr("\"mm\", \"cm\", \"dm\", \"m\""));
  EXPECT_THAT(error_of(R"([1, 2])"), HasSubstr("expected an object"));
}

TEST(JsonReader, OutOfRangeNamesBoundAndUnit) {
  const auto e = error_of(R"({"speed": 150})");
  EXPECT_THAT(e, HasSubstr("test.json: speed: value 150 is out of range"));
  EXPECT_THAT(e, HasSubstr("[0, 100] m/s"));
  EXPECT_THAT(error_of(R"({"inner": {"stiffness": -1}})"), HasSubstr("inner.stiffness"));
  EXPECT_THAT(error_of(R"({"weights": [0.5, 2]})"),
              HasSubstr("weights[1]: value 2 is out of range"));
  EXPECT_THAT(error_of(R"({"count": 0})"), HasSubstr("count: value 0 is out of range"));
  EXPECT_THAT(error_of(R"({"maybe": 3})"), HasSubstr("maybe: value 3 is out of range"));
}

TEST(JsonReader, MissingRequiredKey) {
  const auto e = error_of(R"({"items": [{"label": "a"}]})");
  EXPECT_THAT(e, HasSubstr("items[0]: missing required key \"id\""));
}

TEST(JsonParse, SyntaxErrorHasLineAndColumn) {
  try {
    parse_json_text("{\n  \"a\": 1,\n  \"b\": tru\n}\n", "bad.json");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("bad.json:3:"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("invalid JSON"));
    EXPECT_THAT(std::string(e.what()), ::testing::Not(HasSubstr("json.exception")));
  }
}

TEST(JsonParse, ANumberTooLargeForADoubleNamesFileLineAndColumn) {
  // Regression: "1e999" printed nlohmann's raw out_of_range exception without file or line.
  try {
    parse_json_text("{\n  \"a\": 1,\n  \"seed\": 1e999\n}\n", "big.json");
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_THAT(m, HasSubstr("big.json:3:11"));
    EXPECT_THAT(m, HasSubstr("1e999"));
    EXPECT_THAT(m, HasSubstr("invalid JSON"));
    EXPECT_THAT(m, ::testing::Not(HasSubstr("json.exception")));
  }
}

TEST(JsonParse, DuplicateKeyIsAnError) {
  EXPECT_THROW(parse_json_text(R"({"a": 1, "a": 2})", "dup.json"), Error);
  // The same key in different objects is fine.
  EXPECT_NO_THROW(parse_json_text(R"({"a": {"a": 1}, "b": {"a": 2}})", "ok.json"));
}

TEST(JsonParse, FileErrors) {
  const auto dir = test::scratch_dir("json");
  EXPECT_THROW(parse_json_file(dir / "missing.json"), Error);
  std::ofstream(dir / "empty.json") << "";
  EXPECT_THROW(parse_json_file(dir / "empty.json"), Error);
  std::ofstream(dir / "bytes.json") << std::string("\x01\xff\xfe garbage", 11);
  try {
    parse_json_file(dir / "bytes.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("bytes.json:1:"));
  }
}

TEST(JsonWriter, RoundTripsThroughReader) {
  Outer o;
  o.speed = 1.25;
  o.mode = Mode::Careful;
  o.units = LengthUnit::dm;
  o.inner.axis = Vec3(0.5, -0.5, 0.25);
  o.items = {Item{1, "a"}, Item{2, "b"}};
  o.weights = {0.1, 0.9};
  o.named["q"].stiffness = 3.0;
  o.maybe = 0.75;
  const Json j = to_json(o);
  EXPECT_EQ(j["mode"], "careful");
  EXPECT_EQ(j["units"], "dm");
  Outer back;
  read_json(j, "", back, JsonSource{"mem"});
  EXPECT_EQ(to_json(back), j);
  EXPECT_EQ(back.inner.axis, o.inner.axis);
  EXPECT_EQ(back.items[1].label, "b");
  // Absent optional is left out.
  Outer none;
  EXPECT_FALSE(to_json(none).contains("maybe"));
}

TEST(JsonDoc, EveryKeyHasARowWithTypeUnitDefaultAndRange) {
  const auto rows = doc_rows<Outer>("");
  auto find = [&](const std::string& key) -> const DocRow* {
    for (const auto& r : rows)
      if (r.key == key) return &r;
    return nullptr;
  };
  const DocRow* speed = find("speed");
  ASSERT_NE(speed, nullptr);
  EXPECT_EQ(speed->type, "number");
  EXPECT_EQ(speed->unit, "m/s");
  EXPECT_EQ(speed->default_value, "`5.0`");
  EXPECT_EQ(speed->range, "[0, 100]");
  ASSERT_NE(find("inner.stiffness"), nullptr);
  ASSERT_NE(find("inner.axis"), nullptr);
  EXPECT_EQ(find("inner.axis")->type, "array of 3 numbers");
  ASSERT_NE(find("items[].id"), nullptr);
  EXPECT_EQ(find("items[].id")->default_value, "required");
  ASSERT_NE(find("named.<name>.stiffness"), nullptr);
  EXPECT_THAT(find("mode")->type, HasSubstr("\"careful\""));
  const std::string table = doc_table(rows);
  EXPECT_THAT(table, HasSubstr("| `speed` | number | m/s |"));
}

TEST(JsonReader, SuggestionPrefersTruncatedNames) {
  // "fov" is closer to "far" by edit distance, but a truncated "fov_deg" is the likelier intent.
  EXPECT_EQ(suggest("fov", {"eye", "far", "fov_deg"}), "fov_deg");
  EXPECT_EQ(suggest("widht", {"width", "height"}), "width");
  EXPECT_EQ(suggest("zzzzzz", {"width", "height"}), "");
}
