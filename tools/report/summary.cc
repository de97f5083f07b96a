// SPDX-License-Identifier: MIT
#include "report/summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

namespace cbrdf::report {
namespace {

std::string db_with_gain(double psnr, double paper) {
  return format_value("%.2f", psnr) + " (" + format_value("%+.2f", psnr - paper) + ")";
}

// The label chosen most often among the picks, with its count (ties: the first met).
std::pair<std::string, int> most_often(const std::vector<std::string>& labels) {
  std::vector<std::pair<std::string, int>> counts;
  for (const std::string& l : labels) {
    auto it =
        std::find_if(counts.begin(), counts.end(), [&](const auto& c) { return c.first == l; });
    if (it == counts.end()) {
      counts.emplace_back(l, 1);
    } else {
      ++it->second;
    }
  }
  std::pair<std::string, int> best{"", 0};
  for (const auto& c : counts) {
    if (c.second > best.second) best = c;
  }
  return best;
}

// Means over the materials that have the pick, and the setting chosen most often.
struct PickMean {
  int n = 0;
  double bytes = 0, psnr = 0, gain = 0;
  std::pair<std::string, int> most{"", 0};
};
PickMean pick_mean(const std::vector<MaterialAnswer>& answers, bool MaterialAnswer::*has,
                   RdPoint MaterialAnswer::*pick) {
  PickMean m;
  std::vector<std::string> labels;
  for (const MaterialAnswer& a : answers) {
    if (!(a.*has)) continue;
    const RdPoint& p = a.*pick;
    m.bytes += p.bytes, m.psnr += p.psnr, m.gain += p.psnr - a.paper.psnr;
    labels.push_back(p.label);
    ++m.n;
  }
  if (m.n) m.bytes /= m.n, m.psnr /= m.n, m.gain /= m.n;
  m.most = most_often(labels);
  return m;
}

std::vector<MaterialAnswer> answers_of(const std::vector<MaterialResult>& results) {
  std::vector<MaterialAnswer> out;
  for (const MaterialResult& m : results) out.push_back(material_answer(material_points(m)));
  return out;
}

// `cbrdf encode` options that select a setting of the sweep (or the paper's).
std::string encode_command(const std::string& label, const Settings& st) {
  std::vector<CodecSetting> known = st.sweep.settings();
  known.push_back(paper_setting());
  for (const CodecSetting& s : known) {
    if (s.label() != label) continue;
    std::string cmd = "cbrdf encode IN.binary -o OUT.cbrdf";
    if (s.family != "frank") cmd += " --family " + s.family;
    cmd += " --slices " + std::to_string(s.slices) + " --bits " + bits_name(s.bits);
    if (s.components != 1) cmd += " --components " + components_name(s.components);
    if (s.max_error > 0) {
      char text[64];
      std::snprintf(text, sizeof text, " --max-error %g --residual-steps visibility", s.max_error);
      cmd += text;
    }
    return cmd;
  }
  return "";
}

}  // namespace

MaterialAnswer material_answer(const MaterialPoints& m) {
  MaterialAnswer a;
  a.material = m.material;
  if (!m.has_paper) return a;
  a.has_paper = true;
  a.paper = m.paper;
  std::vector<RdPoint> candidates = m.sweep;
  const bool in_sweep = std::any_of(candidates.begin(), candidates.end(),
                                    [&](const RdPoint& p) { return p.label == m.paper.label; });
  if (!in_sweep) candidates.push_back(m.paper);
  if (const RdPoint* p = best_within(candidates, m.paper.bytes)) a.has_same = true, a.same = *p;
  if (const RdPoint* p = best_within(candidates, kSmallBudgetFactor * m.paper.bytes)) {
    a.has_small = true, a.small = *p;
  }
  return a;
}

TextTable answer_table(const std::vector<MaterialResult>& results) {
  const std::vector<MaterialAnswer> answers = answers_of(results);
  TextTable t;
  t.id = "summary";
  t.title = "Summary: the paper's setting (" + paper_setting().label() +
            ") against the best setting within its bytes and within a quarter of them";
  t.note =
      "Per material, among the sweep's settings and the paper's own: the one with the highest "
      "tone-mapped sphere PSNR within the paper setting's .cbrdf bytes, and within a quarter of "
      "them; in brackets its dB against the paper's setting. '-': no setting fits.";
  t.header = {"material",  "paper bytes",     "paper dB", "best within 1x", "bytes",
              "dB (gain)", "best within 1/4", "bytes",    "dB (gain)"};
  for (const MaterialAnswer& a : answers) {
    std::vector<std::string> row{a.material, "-", "-", "-", "-", "-", "-", "-", "-"};
    if (a.has_paper)
      row[1] = format_value("%.0f", a.paper.bytes), row[2] = format_value("%.2f", a.paper.psnr);
    if (a.has_same) {
      row[3] = a.same.label, row[4] = format_value("%.0f", a.same.bytes);
      row[5] = db_with_gain(a.same.psnr, a.paper.psnr);
    }
    if (a.has_small) {
      row[6] = a.small.label, row[7] = format_value("%.0f", a.small.bytes);
      row[8] = db_with_gain(a.small.psnr, a.paper.psnr);
    }
    t.rows.push_back(std::move(row));
  }
  if (answers.size() > 1) {
    const PickMean paper = pick_mean(answers, &MaterialAnswer::has_paper, &MaterialAnswer::paper);
    std::vector<std::string> row{"mean", format_value("%.0f", paper.bytes),
                                 format_value("%.2f", paper.psnr)};
    for (auto [has, pick] : {std::pair{&MaterialAnswer::has_same, &MaterialAnswer::same},
                             std::pair{&MaterialAnswer::has_small, &MaterialAnswer::small}}) {
      const PickMean m = pick_mean(answers, has, pick);
      if (m.n == 0) {
        row.insert(row.end(), {"-", "-", "-"});
        continue;
      }
      row.push_back("most often " + m.most.first + " (" + std::to_string(m.most.second) + "/" +
                    std::to_string(m.n) + ")");
      row.push_back(format_value("%.0f", m.bytes));
      row.push_back(format_value("%.2f", m.psnr) + " (" + format_value("%+.2f", m.gain) + ")");
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

std::string answer_paragraph(const std::vector<MaterialResult>& results, const Settings& st) {
  const std::vector<MaterialAnswer> answers = answers_of(results);
  const PickMean paper = pick_mean(answers, &MaterialAnswer::has_paper, &MaterialAnswer::paper);
  if (paper.n == 0) return "";
  const std::string label = paper_setting().label();
  const double input = mean_of(results, label, &Row::input_bytes);
  std::ostringstream out;
  out << "On " << paper.n << (paper.n == 1 ? " material" : " materials")
      << ", the paper's setting (" << label << ") takes " << format_value("%.0f", paper.bytes)
      << " bytes" << (paper.n == 1 ? "" : " on average") << " ("
      << format_value("%.0f", input / paper.bytes) << ":1 against the MERL table) at "
      << format_value("%.2f", paper.psnr) << " dB tone-mapped sphere PSNR. ";
  if (st.sweep.only_paper_setting()) {
    out << "The sweep held only the paper's setting, so there is nothing to compare it with: add "
           "e.g. "
        << kFrontierSweepExample << " for the rate-distortion frontier.";
    return out.str();
  }
  const PickMean same = pick_mean(answers, &MaterialAnswer::has_same, &MaterialAnswer::same);
  const PickMean small = pick_mean(answers, &MaterialAnswer::has_small, &MaterialAnswer::small);
  auto describe = [&](const PickMean& m) {
    out << "the best setting" << (paper.n == 1 ? " (" : " per material (most often ")
        << m.most.first
        << (paper.n == 1 ? "" : ", " + std::to_string(m.most.second) + " of " + std::to_string(m.n))
        << ") takes " << format_value("%.0f", m.bytes) << " bytes at "
        << format_value("%.2f", m.psnr) << " dB (" << format_value("%+.2f", m.gain) << " dB)";
  };
  out << "Within its bytes, ";
  describe(same);
  if (small.n > 0) {
    out << "; within a quarter of its bytes, ";
    describe(small);
    if (small.n < paper.n) out << " on the " << small.n << " materials where one fits";
    out << ".";
  } else {
    out << "; no setting of the sweep fits in a quarter of its bytes (add fewer bits, slices or "
           "components to the sweep).";
  }
  return out.str();
}

std::string closing_summary(const std::vector<MaterialResult>& results, const Settings& st,
                            const std::string& html_path) {
  std::ostringstream out;
  out << to_text(answer_table(results)) << "\n" << answer_paragraph(results, st) << "\n";
  const PickMean same =
      pick_mean(answers_of(results), &MaterialAnswer::has_same, &MaterialAnswer::same);
  const std::string cmd = same.n ? encode_command(same.most.first, st) : "";
  if (!cmd.empty() && !st.sweep.only_paper_setting()) {
    out << "Encode with the setting chosen most often within the paper's bytes: " << cmd << "\n";
  }
  if (html_path.empty()) {
    out << "No report files were written: add -o DIR for report.html with the figures.\n";
  } else {
    out << "Full report: " << html_path << "\n";
  }
  return out.str();
}

}  // namespace cbrdf::report
