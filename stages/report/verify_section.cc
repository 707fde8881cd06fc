#include "stages/report/verify_section.h"

#include <fmt/format.h>

#include "common/io/eigen_proto.h"
#include "stages/report/html_escape.h"

namespace tiltcal::report {
namespace {

std::string VerdictName(proto::VerifyResult::Verdict v) {
  return v == proto::VerifyResult::VERDICT_UNSET ? "UNSET" : proto::VerifyResult::Verdict_Name(v);
}

std::string Vector(const proto::Vector3& v, double scale, const char* format) {
  return fmt::format(fmt::runtime(std::string("(") + format + ", " + format + ", " + format + ")"),
                     scale * v.x(), scale * v.y(), scale * v.z());
}

// "0" (none detected) shown as "none".
std::string Detectable(const proto::Vector3& v, double scale) {
  const auto one = [scale](double x) {
    return x > 0.0 ? fmt::format("{:.3g}", scale * x) : std::string("none");
  };
  return "(" + one(v.x()) + ", " + one(v.y()) + ", " + one(v.z()) + ")";
}

}  // namespace

std::string VerifySection(const VerifyPage& verify) {
  const proto::VerifyResult& r = verify.result;
  const std::string verdict = VerdictName(r.verdict());
  std::string out = fmt::format(
      "<section class=\"verify\" id=\"verify\">\n<h2>Check against a stored calibration: <span "
      "class=\"verdict verdict-{0}\">{0}</span></h2>\n<p>Each sequence calibrated again and "
      "compared with the reference <code>{1}</code> ({2}, tiltcal_verify).</p>\n"
      "<ul class=\"reasons\">\n",
      verdict, EscapeHtml(r.reference()), LinkOrText(verify.link));
  for (const std::string& reason : r.verdict_reasons()) {
    out += "<li>" + EscapeHtml(reason) + "</li>\n";
  }
  out += "</ul>\n<table class=\"verify-sequences\">\n<tr><th>sequence</th><th>verdict</th>"
         "<th>χ² / limit (dof)</th><th>rotation deg, b (σ)</th>"
         "<th>translation mm, b (σ)</th><th>τ ms (σ)</th>"
         "<th>smallest moves detected: deg about b-x, y, z; mm along b-x, y, z; ms</th>"
         "<th>map thickness mm: estimate / reference</th></tr>\n";
  for (const proto::SequenceVerification& s : r.sequences()) {
    const std::string name = EscapeHtml(s.name());
    const std::string v = VerdictName(s.verdict());
    if (s.dof() == 0) {
      out += fmt::format(
          "<tr><td>{0}</td><td class=\"verdict-{1}\">{1}</td><td colspan=\"6\">—</td></tr>\n",
          name, v);
      continue;
    }
    out += fmt::format(
        "<tr><td>{}</td><td class=\"verdict-{}\">{}</td><td>{:.1f} / {:.1f} ({})</td>"
        "<td>{} ({:.1f})</td><td>{} ({:.1f})</td><td>{:+.3f} ({:.1f})</td>"
        "<td>{}; {}; {}</td><td>{:.2f} / {:.2f}</td></tr>\n",
        name, v, v, s.chi2(), s.limit(), s.dof(),
        Vector(s.rotation_difference_deg(), 1.0, "{:+.3f}"), s.rotation_difference_sigma(),
        Vector(s.translation_difference_m(), 1e3, "{:+.1f}"), s.translation_difference_sigma(),
        1e3 * s.time_offset_difference_s(), s.time_offset_difference_sigma(),
        Detectable(s.detectable_rotation_deg(), 1.0),
        Detectable(s.detectable_translation_m(), 1e3),
        s.detectable_time_offset_s() > 0.0
            ? fmt::format("{:.3g}", 1e3 * s.detectable_time_offset_s())
            : std::string("none"),
        1e3 * s.map_sharpness_estimate().median_thickness_m(),
        1e3 * s.map_sharpness_reference().median_thickness_m());
  }
  out += "</table>\n";
  for (const proto::SequenceVerification& s : r.sequences()) {
    out += fmt::format("<h3>{}: <span class=\"verdict-{}\">{}</span></h3>\n<ul class=\"reasons\">\n",
                       EscapeHtml(s.name()), VerdictName(s.verdict()), VerdictName(s.verdict()));
    for (const std::string& reason : s.reasons()) out += "<li>" + EscapeHtml(reason) + "</li>\n";
    out += "</ul>\n";
  }
  return out + "</section>\n";
}

}  // namespace tiltcal::report
