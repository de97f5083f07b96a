// SPDX-License-Identifier: MIT
// cbrdf.encode: the keywords as the encoder's text options (cbrdf/encoder_options.h), checked by
// the library's one validate() and worded with Python's spelling ("max_error="), then the encode
// on the calling thread with the GIL released. Its progress callback takes the GIL back only to
// let Ctrl-C through (KeyboardInterrupt) and to call the caller's progress= function. Returns the
// bytes and what `cbrdf encode` prints about them (the search's choice, whether the target was
// met, its note, the noise estimate), which cbrdf/__init__.py turns into attributes and warnings.
#include <pybind11/pybind11.h>

#include <climits>
#include <cmath>
#include <exception>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "arguments.h"
#include "bindings.h"
#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/encoder_settings.h"
#include "cbrdf/noise.h"
#include "cbrdf/rate_control.h"
#include "errors.h"
#include "tables.h"

namespace cbrdf::python {
namespace {

// A setting's neutral name as the keyword of cbrdf.encode: "max_error=", "level=".
std::string python_spelling(std::string_view setting) {
  if (setting == "zstd_level") return "level=";
  return std::string(setting) + "=";
}

[[noreturn]] void raise_problems(const std::vector<SettingProblem>& problems) {
  raise_status(settings_status(problems, python_spelling), 2);
}

// A count (an int, any size) or "auto", as the text the encoder's options take: the library
// words every value it refuses. A str other than "auto" is refused here: a count is an int, as
// the stubs say ("3" would be an easy slip to accept).
std::string count_text(const py::object& v, const char* name) {
  if (py::isinstance<py::bool_>(v)) {
    raise_type(python_spelling(name) + " must be an int or 'auto', not a bool");
  }
  if (PyIndex_Check(v.ptr()) && !py::isinstance<py::float_>(v)) {
    py::object i = py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr()));
    if (!i) throw py::error_already_set();
    return py::str(i).cast<std::string>();
  }
  if (py::isinstance<py::str>(v)) {
    const std::string s = str_arg(v, name);
    if (s != "auto" && !s.empty() && s.find_first_not_of("0123456789") == std::string::npos) {
      raise_invalid(
          python_spelling(name) + " must be an int or 'auto', not the str " + repr_text(v), 2);
    }
    return s;
  }
  raise_type(python_spelling(name) + " must be an int or 'auto', not " + repr_text(v));
}

// An int keyword (a Python int or a NumPy integer; not a bool or a float). Its range is the
// library's to check; a value no C int holds cannot be passed on and is refused here.
int int_value(const py::handle& v, const char* name) {
  if (py::isinstance<py::bool_>(v) || !PyIndex_Check(v.ptr()) || py::isinstance<py::float_>(v)) {
    raise_type(python_spelling(name) + " must be an int, not " + repr_text(v));
  }
  py::object i = py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr()));
  if (!i) throw py::error_already_set();
  int overflow = 0;
  const long long x = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
  if (overflow != 0 || x < INT_MIN || x > INT_MAX) {
    raise_invalid(python_spelling(name) + " is out of range, not " + repr_text(v), 2);
  }
  return int(x);
}

// A real keyword (int, float or a NumPy real), or 0 ("none", as the library reads it) for None.
double real_or_zero(const py::object& v, const char* name) {
  if (v.is_none()) return 0.0;
  const std::optional<double> x = real_value(v);
  if (!x) {
    raise_type(python_spelling(name) + " must be a number (an int or a float), not " +
               repr_text(v));
  }
  return *x;
}

// The keywords of cbrdf.encode, as Python gave them.
struct EncodeArgs {
  py::object make_table, bits, components, slices, family, loss, level, placement;
  bool naive_marginals = false;
  py::object threads, target_bytes, target_psnr, max_error;
  bool lossless = false;
  py::object source_name, mixture_copulas, format_version, metadata, residual_steps, progress;
};

EncoderOptions options_of(const EncodeArgs& a) {
  EncoderOptions o;
  o.slices = count_text(a.slices, "slices");
  o.components = count_text(a.components, "components");
  o.bits = count_text(a.bits, "bits");
  o.family = str_arg(a.family, "family");
  o.loss = str_arg(a.loss, "loss");
  o.placement = str_arg(a.placement, "placement");
  if (!a.mixture_copulas.is_none())
    o.mixture_copulas = str_arg(a.mixture_copulas, "mixture_copulas");
  o.format_version = str_arg(a.format_version, "format_version");
  o.metadata = str_arg(a.metadata, "metadata");
  if (!a.residual_steps.is_none()) o.residual_steps = str_arg(a.residual_steps, "residual_steps");
  o.zstd_level = int_value(a.level, "zstd_level");
  o.threads = int_value(a.threads, "threads");
  o.naive_marginals = a.naive_marginals;
  o.lossless = a.lossless;
  o.max_error = real_or_zero(a.max_error, "max_error");
  if (!a.source_name.is_none()) o.source_name = str_arg(a.source_name, "source_name");
  return o;
}

// target_bytes= and target_psnr= as a RateTarget (both 0: none), and the residual keywords
// beside them, in the order `cbrdf encode` checks them; every problem goes to *problems.
RateTarget rate_target(const EncodeArgs& a, const EncoderOptions& o,
                       std::vector<SettingProblem>* problems) {
  RateTarget target;
  // RateTarget takes 0 as no target; a keyword given as 0 asks for one and is refused.
  const auto given_target = [&](const char* setting, const py::object& v, double* out) {
    if (v.is_none()) return;
    *out = real_or_zero(v, setting);
    if (*out == 0) {
      problems->push_back(
          {setting, "must be above 0, not " + repr_text(v) + " (leave it out for none)"});
    }
  };
  // The command's parser refuses both options together (CLI11's excludes), before validation.
  if (!a.target_bytes.is_none() && !a.target_psnr.is_none()) {
    problems->push_back({"target_bytes", "and {target_psnr} exclude each other; give one of them"});
  }
  given_target("target_bytes", a.target_bytes, &target.max_bytes);
  given_target("target_psnr", a.target_psnr, &target.min_psnr);
  for (SettingProblem& p : validate(target)) problems->push_back(std::move(p));
  const bool targeted = !a.target_bytes.is_none() || !a.target_psnr.is_none();
  if (auto conflict = residual_option_conflict(
          {targeted, !a.max_error.is_none(), a.lossless, !a.residual_steps.is_none()})) {
    problems->push_back(std::move(*conflict));
  }
  // Rate control chooses the slice count itself.
  if (targeted && o.slices == "auto") {
    problems->push_back({"slices",
                         "auto and a target ({target_bytes}, {target_psnr}) both choose the slice "
                         "count; give one of them"});
  }
  return target;
}

// The settings and target the keywords stand for, or cbrdf.Error naming every problem.
std::pair<EncoderSettings, RateTarget> settings_of(const EncodeArgs& a, const EncoderOptions& o) {
  std::vector<SettingProblem> problems;
  RateTarget target = rate_target(a, o, &problems);
  ParsedOptions parsed = parse_options(o);
  problems.insert(problems.end(), parsed.problems.begin(), parsed.problems.end());
  if (!problems.empty()) raise_problems(problems);
  // Given explicitly, mixture_copulas applies to the search too (as --mixture-copulas).
  if (!a.mixture_copulas.is_none()) target.mixture_copulas = parsed.settings.fit.mixture_copulas;
  // An explicit components=K > 1 caps the search, as in `cbrdf encode`.
  const FitSettings& fit = parsed.settings.fit;
  const bool targeted = target.max_bytes > 0 || target.min_psnr > 0;
  if (targeted && !fit.auto_components && fit.components > 1) {
    target.max_components = fit.components;
  }
  return {std::move(parsed.settings), target};
}

// EncoderSettings::progress for a call from Python: with the GIL taken back, pending signals are
// handled (Ctrl-C) and the caller's progress(fraction, stage) is called; either raising, or the
// function returning False, cancels the encode. The exception is kept for the caller's thread.
class ProgressBridge {
 public:
  explicit ProgressBridge(py::object user) : user_(std::move(user)) {}

  bool operator()(const EncodeProgress& p) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) return keep_error();
    if (user_.is_none()) return true;
    try {
      const py::object r = user_(p.fraction, py::str(p.stage.data(), p.stage.size()));
      if (r.ptr() == Py_False) cancelled_by_user_ = true;
      return !cancelled_by_user_;
    } catch (py::error_already_set& e) {
      e.restore();
      return keep_error();
    }
  }

  // After the encode, with the GIL held: raises what stopped it, if anything did.
  void rethrow() {
    if (error_) {
      error_->restore();
      error_.reset();
      throw py::error_already_set();
    }
  }

 private:
  bool keep_error() {
    error_.emplace();  // takes the pending Python exception
    return false;
  }

  py::object user_;
  std::optional<py::error_already_set> error_;
  bool cancelled_by_user_ = false;
};

// What an encode found besides its bytes: what `cbrdf encode` prints about a targeted encode (the
// chosen setting, whether the target was met, the ladder's note) and the noise estimate behind the
// note.
struct EncodeFacts {
  int bits = 0;
  std::optional<RateResult> rate;  // targeted encodes only (its `encoded` emptied)
  std::optional<NoiseEstimate> noise;
};

// The noise estimate the ladder's note rests on (the same table and threads: the same numbers):
// without its sphere renders first, which take most of its time, and with them only for a noisy
// table, whose ceiling the note names.
NoiseEstimate noise_of(const BrdfTable& table, int threads) {
  NoiseOptions o;
  o.threads = threads;
  o.ceiling = false;
  NoiseEstimate e = estimate_noise(table, o);
  if (!e.noisy()) return e;
  o.ceiling = true;
  return estimate_noise(table, o);
}

// The encode with the GIL released; its errors start with the table's name (the path as given,
// as the command prefixes them; none for arrays).
std::vector<std::uint8_t> run_encode(const PyTable& t, EncoderSettings settings,
                                     const RateTarget& target, bool targeted,
                                     ProgressBridge* bridge, EncodeFacts* facts) {
  const BrdfTable& table = t.table;
  settings.progress = [bridge](const EncodeProgress& p) { return (*bridge)(p); };
  Expected<std::vector<std::uint8_t>> out = std::vector<std::uint8_t>{};
  {
    py::gil_scoped_release release;
    try {
      if (!targeted) {
        auto r = encode_table(table, settings);
        if (r.ok()) facts->bits = r->bits;
        out = r.ok() ? Expected<std::vector<std::uint8_t>>(std::move(r->bytes)) : r.status();
      } else {
        // The whole ladder, as `cbrdf encode --target-*`: the model, then model + residual.
        auto r = encode_to_target_ladder(table, settings, target);
        if (r.ok()) {
          facts->bits = r->encoded.bits;
          out = std::move(r->encoded.bytes);
          r->encoded = EncodeResult{};
          // The estimate explains a missed target or a note; a met target needs none.
          if (!r->met || !r->note.empty()) facts->noise = noise_of(table, settings.fit.threads);
          facts->rate = std::move(*r);
        } else {
          out = r.status();
        }
      }
    } catch (const std::exception& e) {
      out = error(ErrorCode::kInternal, std::string("encoding failed: ") + e.what());
    }
  }
  bridge->rethrow();
  return take(std::move(out), t.name);
}

// The facts as the dict cbrdf/__init__.py reads (None where an encode has no such fact).
py::dict facts_dict(const EncodeFacts& f, const RateTarget& target) {
  py::dict d;
  d["bits"] = f.bits;
  const py::object none = py::none();
  d["target_met"] = f.rate ? py::object(py::bool_(f.rate->met)) : none;
  d["target_bytes"] = target.max_bytes > 0 ? py::object(py::float_(target.max_bytes)) : none;
  d["target_psnr"] = target.min_psnr > 0 ? py::object(py::float_(target.min_psnr)) : none;
  if (f.rate) {
    const RateCandidate& c = f.rate->chosen;
    d["nbytes"] = c.bytes;
    d["psnr_tonemapped"] = c.psnr_tonemapped;
    d["psnr_linear"] = c.psnr_linear;
    d["slices"] = c.slices;
    d["components"] = c.components;
    d["max_error"] = c.max_error;
    d["settings_tried"] = f.rate->tried.size();
    d["note"] = f.rate->note.empty() ? none : py::object(py::str(f.rate->note));
    d["residual_of_smoothed_input"] = f.rate->residual_of_smoothed_input;
  }
  if (f.noise) {
    d["noisy"] = f.noise->noisy();
    d["noise_sigma"] = f.noise->max_sigma();
    d["noise_floor_error"] =
        f.noise->noisy() ? py::object(py::float_(noise_floor_error(*f.noise))) : none;
    d["psnr_ceiling_tonemapped"] =
        f.noise->noisy() ? py::object(py::float_(f.noise->psnr_ceiling_tonemapped)) : none;
  }
  return d;
}

// `make_table()` gives the cbrdf._Table, called once every option has been checked: reading or
// converting a table takes a while, and a bad option is refused at once.
py::tuple encode(const EncodeArgs& a) {
  EncoderOptions o = options_of(a);
  auto [settings, target] = settings_of(a, o);
  const bool targeted = target.max_bytes > 0 || target.min_psnr > 0;
  const py::object table_obj = a.make_table();
  const PyTable& t = table_obj.cast<const PyTable&>();
  t.ok();
  if (a.source_name.is_none()) settings.container.source_name = t.source_name;
  if (a.lossless && t.folded_from_360) {
    raise_invalid(t.name +
                      ": lossless cannot keep a 90x90x360 file exactly (it is read as 180 phi_d "
                      "bins, each the mean of phi_d and phi_d + 180); convert it with "
                      "cbrdf.write_merl first if that table is what you want",
                  2);
  }
  ProgressBridge bridge(a.progress);
  EncodeFacts facts;
  auto out = run_encode(t, std::move(settings), target, targeted, &bridge, &facts);
  return py::make_tuple(py::bytes(reinterpret_cast<const char*>(out.data()), out.size()),
                        facts_dict(facts, target));
}

}  // namespace

void bind_encode(py::module_& m) {
  m.def(
      "_encode",
      [](py::object make_table, py::object bits, py::object components, py::object slices,
         py::object family, py::object loss, py::object level, py::object placement,
         bool naive_marginals, py::object threads, py::object target_bytes, py::object target_psnr,
         py::object max_error, bool lossless, py::object source_name, py::object mixture_copulas,
         py::object format_version, py::object metadata, py::object residual_steps,
         py::object progress) {
        return encode(EncodeArgs{make_table,      bits,     components,     slices,
                                 family,          loss,     level,          placement,
                                 naive_marginals, threads,  target_bytes,   target_psnr,
                                 max_error,       lossless, source_name,    mixture_copulas,
                                 format_version,  metadata, residual_steps, progress});
      },
      py::arg("table"), py::arg("bits"), py::arg("components"), py::arg("slices"),
      py::arg("family"), py::arg("loss"), py::arg("level"), py::arg("placement"),
      py::arg("naive_marginals"), py::arg("threads"), py::arg("target_bytes"),
      py::arg("target_psnr"), py::arg("max_error"), py::arg("lossless"), py::arg("source_name"),
      py::arg("mixture_copulas"), py::arg("format_version"), py::arg("metadata"),
      py::arg("residual_steps"), py::arg("progress"));
}

}  // namespace cbrdf::python
