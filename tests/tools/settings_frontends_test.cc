// SPDX-License-Identifier: MIT
// One refusal per bad encoder setting in every front end: each case of
// tests/data/bad_settings.json through the C++ API (validate(), encode_table, encode_to_target),
// the C API and the `cbrdf encode` command, each saying the same message after its own name of
// the setting. Python's half reads the same file (tests/python).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/cbrdf_encode.h"
#include "cbrdf/encoder.h"
#include "cbrdf/encoder_settings.h"
#include "cbrdf/rate_control.h"
#include "test_support.h"

namespace cbrdf {
namespace {

using nlohmann::json;

const json& data() {
  static const json d = [] {
    std::ifstream in(std::string(CBRDF_TEST_DATA_DIR) + "/bad_settings.json");
    return json::parse(in);
  }();
  return d;
}

// The case's refusal in front end `fe`'s words, built here from the file alone: the front end's
// name of the setting, then the message with every {name} replaced by the front end's name.
std::string expected(const json& c, const std::string& fe) {
  const json& spellings = data().at("spellings");
  const auto spell = [&](const std::string& setting) {
    return spellings.at(setting).at(fe).get<std::string>();
  };
  std::string message = c.at("message").get<std::string>();
  for (std::size_t open; (open = message.find('{')) != std::string::npos;) {
    const std::size_t close = message.find('}', open);
    message.replace(open, close - open + 1, spell(message.substr(open + 1, close - open - 1)));
  }
  return spell(c.at("setting").get<std::string>()) + " " + message;
}

std::string label(const json& c) {
  return c.at("setting").get<std::string>() + " " + c.dump();
}

TEST(SettingsFrontEnds, TheFileHoldsAtLeastTwelveCasesEachWithEveryFrontEnd) {
  const json& cases = data().at("cases");
  ASSERT_GE(cases.size(), 12u);
  for (const json& c : cases) {
    for (const char* fe : {"cli", "c", "python", "cxx"}) {
      EXPECT_TRUE(c.contains(fe)) << fe << " missing in " << label(c);
    }
    EXPECT_TRUE(data().at("spellings").contains(c.at("setting").get<std::string>())) << label(c);
  }
}

// EncoderSettings and RateTarget members, as the file names them.
void set_member(const std::string& member, const json& v, EncoderSettings* st, RateTarget* t) {
  if (member == "fit.slices") {
    st->fit.slices = v.get<int>();
  } else if (member == "fit.components") {
    st->fit.components = v.get<int>();
  } else if (member == "fit.threads") {
    st->fit.threads = v.get<int>();
  } else if (member == "auto_bits.enabled") {
    st->auto_bits.enabled = v.get<bool>();
  } else if (member == "container.bits") {
    st->container.bits = v.get<int>();
  } else if (member == "container.zstd_level") {
    st->container.zstd_level = v.get<int>();
  } else if (member == "residual.max_error") {
    st->residual.max_error = v.get<double>();
  } else if (member == "residual.lossless") {
    st->residual.lossless = v.get<bool>();
  } else if (member == "residual.row_steps") {
    st->residual.row_steps = v.get<bool>();
  } else if (member == "target.min_psnr") {
    t->min_psnr = v.get<double>();
  } else if (member == "target.max_bytes") {
    t->max_bytes = v.get<double>();
  } else {
    ADD_FAILURE() << "the test does not know the member " << member;
  }
}

TEST(SettingsFrontEnds, CxxApiRefusesEachWithOneProblemInItsMembersNames) {
  const BrdfTable table;  // never fitted: the settings are refused first
  for (const json& c : data().at("cases")) {
    SCOPED_TRACE(label(c));
    EncoderSettings st;
    RateTarget target;
    target.max_bytes = 0;
    target.min_psnr = 0;
    bool targeted = false;
    for (const auto& [member, value] : c.at("cxx").items()) {
      set_member(member, value, &st, &target);
      targeted = targeted || member.starts_with("target.");
    }
    const std::vector<SettingProblem> problems = targeted ? validate(target) : validate(st);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_EQ(problems[0].setting, c.at("setting").get<std::string>());
    const std::string want = expected(c, "cxx");
    EXPECT_EQ(settings_status(problems, cxx_spelling).message(), want);
    // The encoder's entry points refuse with the same words, before any work.
    const Status refused =
        targeted ? encode_to_target(table, st, target).status() : encode_table(table, st).status();
    EXPECT_EQ(refused.code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(refused.message(), want);
  }
}

void set_field(const std::string& field, const json& v, cbrdf_encode_settings* s) {
  if (field == "slices") {
    s->slices = v.get<int>();
  } else if (field == "components") {
    s->components = v.get<int>();
  } else if (field == "bits") {
    s->bits = v.get<int>();
  } else if (field == "zstd_level") {
    s->zstd_level = v.get<int>();
  } else if (field == "threads") {
    s->threads = v.get<int>();
  } else if (field == "max_error") {
    s->max_error = v.get<double>();
  } else if (field == "lossless") {
    s->lossless = v.get<int>();
  } else if (field == "residual_steps") {
    s->residual_steps = v.get<int>();
  } else {
    ADD_FAILURE() << "the test does not know the field " << field;
  }
}

TEST(SettingsFrontEnds, CApiRefusesEachWithTheSameMessage) {
  const std::vector<double> values(cbrdf_merl_table_size(), 0.0);
  int checked = 0;
  for (const json& c : data().at("cases")) {
    if (c.at("c").is_null()) continue;  // a setting the C API does not have (rate targets)
    SCOPED_TRACE(label(c));
    cbrdf_encode_settings s;
    ASSERT_EQ(cbrdf_encode_settings_init(&s), CBRDF_OK);
    for (const auto& [field, value] : c.at("c").items()) set_field(field, value, &s);
    void* out = nullptr;
    std::size_t size = 0;
    EXPECT_EQ(cbrdf_encode_table(values.data(), values.size(), &s, &out, &size),
              CBRDF_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(out, nullptr);
    EXPECT_EQ(std::string(cbrdf_last_error_message()), expected(c, "c"));
    ++checked;
  }
  EXPECT_GE(checked, 12);
}

TEST(SettingsFrontEnds, CommandRefusesEachWithTheSameMessageBeforeReadingTheInput) {
  testing::TempDir dir;
  // Not a MERL file: the options are refused before it is read.
  { std::ofstream(dir / "in.binary") << "not read"; }
  for (const json& c : data().at("cases")) {
    SCOPED_TRACE(label(c));
    std::string args =
        "encode " + (dir / "in.binary").string() + " -o " + (dir / "out.cbrdf").string();
    for (const json& a : c.at("cli")) args += " " + a.get<std::string>();
    const testing::CommandResult r = testing::run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    // The whole line: one problem, in the command's words.
    EXPECT_TRUE(
        testing::contains(r.err, "cbrdf: encode: " + expected(c, "cli") + " (see --help)\n"))
        << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.cbrdf"));
  }
}

}  // namespace
}  // namespace cbrdf
