// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/config_keys.h>
#include <msf/common/exceptions.h>
#include <msf/common/json_text.h>
#include <msf/common/line_plot.h>
#include <msf/common/version.h>
#include <msf/common/statistics.h>
#include <msf/common/yaml_file.h>
#include <msf/io/image_io.h>
#include <msf/pipeline/rig_agreement.h>
#include <msf/pipeline/run_report.h>

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iterator>
#include <sstream>

namespace msf {

namespace {

/// What the rows of msf_reconstruct -compare_paper are.
constexpr const char* kPaperRows =
    "`paper`, `mesh_paper`: the paper as published (config/paper.yaml, docs/paper.md), run on the same frames "
    "at the same poses into a map of its own.";

/// The stages reported, with how to read each from a frame row.
struct StageColumn {
  const char* name;
  std::function<double(const RunReport::FrameRow&)> get;
};
const std::vector<StageColumn>& stageColumns() {
  static const std::vector<StageColumn> columns = {
      {"load", [](const RunReport::FrameRow& r) { return r.times.load_ms; }},
      {"lidar", [](const RunReport::FrameRow& r) { return r.times.lidar_ms; }},
      {"stereo", [](const RunReport::FrameRow& r) { return r.times.stereo_ms; }},
      {"depth", [](const RunReport::FrameRow& r) { return r.times.depth_ms; }},
      {"fusion", [](const RunReport::FrameRow& r) { return r.times.fusion_ms; }},
      {"integrate", [](const RunReport::FrameRow& r) { return r.times.integrate_ms; }},
      {"latency", [](const RunReport::FrameRow& r) { return r.latency_ms; }},
  };
  return columns;
}

std::vector<double> column(const std::vector<RunReport::FrameRow>& rows, const StageColumn& c) {
  std::vector<double> values;
  values.reserve(rows.size());
  for (const auto& r : rows)
    values.push_back(c.get(r));
  return values;
}

std::string num(double v, int precision = 4) {
  if (!std::isfinite(v))
    return "null";
  std::ostringstream s;
  s << std::setprecision(precision) << std::fixed << v;
  std::string text = s.str();
  if (text.find('.') == std::string::npos)
    return text;  // an integer's zeros are digits, not padding
  text.erase(text.find_last_not_of('0') + 1);
  if (text.back() == '.')
    text.pop_back();
  return text;
}

void writeText(const std::string& path, const std::string& text) {
  writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << text;
    if (!out)
      throw IOError("cannot write '" + path + "'");
  });
}

std::string metricsJson(const DepthMetrics& m, const std::string& indent) {
  std::ostringstream s;
  s << "{\n"
    << indent << "  \"gt_pixels\": " << m.gt_pixels << ",\n"
    << indent << "  \"coverage\": " << num(m.coverage) << ",\n"
    << indent << "  \"d1_all\": " << num(m.d1_all) << ",\n"
    << indent << "  \"d1_estimated\": " << num(m.d1_estimated) << ",\n"
    << indent << "  \"disparity_mae_px\": " << num(m.disparity_mae_px) << ",\n"
    << indent << "  \"mae_m\": " << num(m.mae_m) << ",\n"
    << indent << "  \"rmse_m\": " << num(m.rmse_m) << "\n"
    << indent << "}";
  return s.str();
}

/// The bars (m^-2) at which summary.json and report.md give a mesh's weight curve: the whole
/// mesh, then sigma 0.45 m, 0.32 m, 0.18 m, 10 cm, 6 cm (a LiDAR return), 3 cm.
constexpr double kWeightBars[] = {0, 5, 10, 30, 100, 300, 1000};

std::string levelJson(const WeightLevel& l) {
  return "{\"min_weight\": " + num(l.min_weight) + ", \"vertices\": " + std::to_string(l.vertices) +
         ", \"accuracy_mean_m\": " + num(l.accuracy_mean_m) + ", \"completeness\": " + num(l.completeness) + "}";
}

std::string accuracyJson(const MeshAccuracy& m) {
  std::string curve;
  if (!m.by_weight.empty())
    for (double bar : kWeightBars)
      curve += std::string(curve.empty() ? "" : ", ") + levelJson(m.by_weight.atWeight(bar));
  std::string bands;
  for (const auto& b : m.by_view_distance)
    bands += std::string(bands.empty() ? "" : ", ") + "{\"lower_m\": " + num(b.lower_m) + ", \"upper_m\": " +
             num(b.upper_m) + ", \"samples\": " + std::to_string(b.samples) + ", \"completeness\": " +
             num(b.completeness) + "}";
  std::string classes;
  for (const auto& c : m.by_class)
    classes += std::string(classes.empty() ? "" : ", ") + "{\"class\": \"" + c.name + "\", \"vertices\": " +
               std::to_string(c.vertices) + ", \"accuracy_mean_m\": " + num(c.accuracy_mean_m) +
               ", \"contribution_m\": " + num(c.contribution_m) + ", \"truth_samples\": " +
               std::to_string(c.truth_samples) + ", \"completeness\": " + num(c.completeness) + "}";
  return "{\"accuracy_mean_m\": " + num(m.accuracy_mean_m) + ", \"accuracy_median_m\": " + num(m.accuracy_median_m) +
         ", \"precision\": " + num(m.precision) + ", \"completeness\": " + num(m.completeness) +
         ", \"threshold_m\": " + num(m.threshold_m) + ", \"cap_m\": " + num(m.cap_m) +
         ", \"mesh_vertices\": " + std::to_string(m.vertices) + ", \"truth_samples\": " +
         std::to_string(m.truth_samples) + ", \"completeness_by_nearest_view\": [" + bands + "]" +
         (curve.empty() ? "" : ", \"by_min_weight\": [" + curve + "]") +
         (classes.empty() ? "" : ", \"by_class\": [" + classes + "]") + "}";
}

std::string skyJson(const SkyCoverage& c) {
  std::ostringstream s;
  s << "{\"frames\": " << c.frames << ", \"sky_pixels\": " << c.sky_pixels
    << ", \"covered_pixels\": " << c.covered_pixels
    << ", \"share\": " << num(c.share, 6) << ", \"mean_frame_share\": " << num(c.mean_frame_share, 6)
    << ", \"worst_share\": " << num(c.worst_share, 6) << ", \"worst_frame\": " << c.worst_frame
    << ", \"covered_depth_median_m\": " << num(c.covered_depth_median_m, 2) << "}";
  return s.str();
}

/// A band's edge: null for the open ends.
std::string edgeJson(double m) { return std::isfinite(m) ? num(m) : "null"; }

std::string offSurfaceJson(const OffSurfaceSplit& o) {
  std::string bands;
  for (const auto& b : o.bands)
    bands += std::string(bands.empty() ? "" : ", ") + "{\"lower_m\": " + edgeJson(b.lower_m) + ", \"upper_m\": " +
             edgeJson(b.upper_m) + ", \"supported_m2\": " + num(b.supported_m2, 3) + ", \"unsupported_m2\": " +
             num(b.unsupported_m2, 3) + ", \"supported_share\": " + num(o.shareOfOff(b.supported_m2), 4) +
             ", \"unsupported_share\": " + num(o.shareOfOff(b.unsupported_m2), 4) + "}";
  return "{\"distance_m\": " + num(o.distance_m) + ", \"area_m2\": " + num(o.area_m2, 2) + ", \"off_area_m2\": " +
         num(o.off_area_m2, 3) + ", \"off_share\": " + num(o.offShare(), 6) + ", \"bands\": [" + bands + "]}";
}

/// A band's heights in words: "below 2 m", "2-5 m", "above 5 m".
std::string bandText(const OffSurfaceSplit::Band& b) {
  if (!std::isfinite(b.lower_m))
    return "below " + num(b.upper_m) + " m";
  if (!std::isfinite(b.upper_m))
    return "above " + num(b.lower_m) + " m";
  return num(b.lower_m) + "–" + num(b.upper_m) + " m";
}

/// What a second stop signal left out, as a sentence of report.md ("" when nothing was).
std::string skippedSentence(const std::vector<std::string>& skipped) {
  if (skipped.empty())
    return "";
  std::string list;
  for (std::size_t k = 0; k < skipped.size(); ++k)
    list += (k ? ", `" : "`") + skipped[k] + "`";
  return " Stopped a second time: skipped " + list + ".";
}

/// A value of a configuration as JSON: numbers as numbers, booleans as booleans, words as
/// strings, sequences as arrays.
std::string configValueJson(const YAML::Node& node) {
  if (node.IsSequence()) {
    std::string out = "[";
    for (std::size_t i = 0; i < node.size(); ++i)
      out += (i ? ", " : "") + configValueJson(node[i]);
    return out + "]";
  }
  if (const std::optional<long long> whole = yamlInteger(node))
    return std::to_string(*whole);
  if (const std::optional<double> real = yamlReal(node))
    return std::isfinite(*real) ? configValue(*real) : "null";
  if (const std::optional<bool> flag = yamlBool(node))
    return *flag ? "true" : "false";
  return node.IsScalar() ? jsonString(node.Scalar()) : "null";
}

/// The configuration file `yaml` (sections of keys, as PipelineConfig::print writes it) as
/// a JSON object, a section a line.
std::string configJson(const std::string& yaml) {
  const YAML::Node root = parseYamlText(yaml, "config.yaml", "config");
  std::string out = "{";
  bool first_section = true;
  for (const auto& section : root) {
    out += std::string(first_section ? "" : ",") + "\n    " + jsonString(section.first.Scalar()) + ": {";
    first_section = false;
    bool first_key = true;
    for (const auto& key : section.second) {
      out += std::string(first_key ? "" : ", ") + jsonString(key.first.Scalar()) + ": " + configValueJson(key.second);
      first_key = false;
    }
    out += "}";
  }
  return out + "\n  }";
}

/// summary.json's depth scores: by method, all pixels and, when split, background and foreground.
std::string depthJson(const std::map<std::string, RunReport::DepthScores>& depth) {
  std::ostringstream s;
  s << "{";
  std::size_t k = 0;
  for (const auto& [method, scores] : depth) {
    s << (k++ ? "," : "") << "\n    " << jsonString(method)
      << ": {\n      \"all\": " << metricsJson(scores.all, "      ");
    if (scores.has_split)
      s << ",\n      \"background\": " << metricsJson(scores.background, "      ")
        << ",\n      \"foreground\": " << metricsJson(scores.foreground, "      ");
    s << "\n    }";
  }
  s << (depth.empty() ? "" : "\n  ") << "}";
  return s.str();
}

/// The fused mesh's surest surface that is as complete as each other mesh, as a JSON array.
std::string atCompletenessJson(const RunReport::MapEvaluation& e, const RunReport::MapEvaluation::Row& fused) {
  std::string matched;
  for (const auto& other : e.rows)
    if (&other != &fused && other.has_accuracy)
      matched += std::string(matched.empty() ? "" : ", ") + "{\"mesh\": " + jsonString(other.score.source) +
                 ", \"kept\": " + levelJson(fused.accuracy.by_weight.atCompleteness(other.accuracy.completeness)) +
                 "}";
  return "[" + matched + "]";
}

/// Counts joined by `separator` between `open` and `close`.
std::string countsJoined(const std::vector<std::size_t>& counts, const char* separator, const char* open,
                         const char* close) {
  std::string out = open;
  for (std::size_t i = 0; i < counts.size(); ++i)
    out += (i ? separator : "") + std::to_string(counts[i]);
  return out + close;
}

/// The crumbs' count, and by the frames since their place was left when measured: "13 (10 / 3 / 0)".
std::string crumbsCell(const CrumbMetrics& c) {
  return std::to_string(c.crumbs) +
         (c.by_frames_since_left.empty() ? "" : " " + countsJoined(c.by_frames_since_left, " / ", "(", ")"));
}

/// A row's ghosts and crumbs as two JSON members, each line indented by `in`.
std::string ghostsJson(const RunReport::MapEvaluation::Row& r, const std::string& in) {
  std::ostringstream s;
  s << in << "\"ghosts\": {\"share\": " << num(r.ghosts.share, 6) << ", \"ghost_vertices\": "
    << r.ghosts.ghost_vertices << ", \"vertices\": " << r.ghosts.vertices << ", \"distance_m\": "
    << num(r.ghosts.distance_m) << "},\n"
    << in << "\"crumbs\": {\"crumbs\": " << r.crumbs.crumbs << ", \"crumb_triangles\": " << r.crumbs.crumb_triangles
    << ", \"specks\": " << r.crumbs.specks << ", \"small_pieces\": " << r.crumbs.small_pieces
    << ", \"pieces\": " << r.crumbs.pieces << ", \"max_triangles\": " << r.crumbs.max_triangles;
  if (!r.crumbs.by_frames_since_left.empty())
    s << ", \"by_frames_since_left\": " << countsJoined(r.crumbs.by_frames_since_left, ", ", "[", "]");
  s << "}";
  return s.str();
}

/// The members of one source's row of reconstruction_evaluation: its depth scores, then what it
/// has of accuracy, matched bars, ghosts, the true sky and pieces seen through.
std::string evaluationRowJson(const RunReport::MapEvaluation& e, const RunReport::MapEvaluation::Row& r) {
  const std::string in = "        ";
  std::ostringstream s;
  s << in << "\"within_range\": " << metricsJson(r.score.within_range, in) << ",\n"
    << in << "\"all\": " << metricsJson(r.score.all, in);
  if (e.moving_split)
    s << ",\n" << in << "\"moving_within_range\": " << metricsJson(r.score.moving_within_range, in) << ",\n"
      << in << "\"moving_all\": " << metricsJson(r.score.moving_all, in);
  if (e.transient_split)
    s << ",\n" << in << "\"lasting_within_range\": " << metricsJson(r.score.lasting_within_range, in) << ",\n"
      << in << "\"transient_within_range\": " << metricsJson(r.score.transient_within_range, in);
  if (r.has_accuracy)
    s << ",\n" << in << "\"accuracy\": " << accuracyJson(r.accuracy);
  if (&r == e.fusedCurveRow())
    s << ",\n" << in << "\"at_completeness_of\": " << atCompletenessJson(e, r);
  if (r.has_ghosts)
    s << ",\n" << ghostsJson(r, in);
  if (r.has_accuracy)
    s << ",\n" << in << "\"true_sky\": " << skyJson(r.true_sky) << ",\n"
      << in << "\"true_sky_sheets\": " << skyJson(r.true_sky_sheets) << ",\n"
      << in << "\"off_surface\": " << offSurfaceJson(r.off_surface);
  if (r.has_seen_through)
    s << ",\n" << in << "\"seen_through\": {\"pieces\": " << r.seen_through.seen_through << ", \"triangles\": "
      << r.seen_through.triangles << ", \"small_pieces\": " << r.seen_through.small_pieces
      << ", \"all_pieces\": " << r.seen_through.pieces << ", \"max_triangles\": " << r.seen_through.max_triangles
      << "}";
  return s.str();
}

/// summary.json's reconstruction_evaluation: the ground truth and a row per source ("null" without rows).
std::string mapEvaluationJson(const RunReport::MapEvaluation& e) {
  if (e.rows.empty())
    return "null";
  std::ostringstream s;
  s << "{\n    \"truth\": " << jsonString(e.truth) << ", \"range_m\": " << num(e.range_m)
    << ", \"frames\": " << e.frames << ", \"gt_pixels\": " << e.gt_pixels
    << ", \"moving_split\": " << (e.moving_split ? "true" : "false")
    << ", \"transient_split\": " << (e.transient_split ? "true" : "false")
    << ",\n    \"no_ghosts\": " << (e.no_ghosts.empty() ? "null" : jsonString(e.no_ghosts)) << ",\n    \"rows\": {";
  for (std::size_t row = 0; row < e.rows.size(); ++row)
    s << (row ? "," : "") << "\n      " << jsonString(e.rows[row].score.source) << ": {\n"
      << evaluationRowJson(e, e.rows[row]) << "\n      }";
  s << "\n    }\n  }";
  return s.str();
}

/// summary.json's open sky: each mesh's cover, a mesh a line ("null" when not measured).
std::string openSkyJson(const std::map<std::string, SkyCoverage>& open_sky) {
  if (open_sky.empty())
    return "null";
  std::ostringstream s;
  for (auto it = open_sky.begin(); it != open_sky.end(); ++it)
    s << (it == open_sky.begin() ? "{" : ",") << "\n    " << jsonString(it->first) << ": " << skyJson(it->second);
  s << "\n  }";
  return s.str();
}

/// report.md's depth errors against ground truth, a row per method (and its split).
void writeDepthTable(std::ostream& s, const std::map<std::string, RunReport::DepthScores>& depth) {
  s << "## Depth against ground truth\n\n"
    << "| method | pixels | coverage | D1 (missing = bad) | D1 on estimates | disparity MAE px | depth MAE m | "
       "depth RMSE m |\n|---|---|---|---|---|---|---|---|\n";
  auto row = [&](const std::string& name, const DepthMetrics& m) {
    s << "| " << name << " | " << m.gt_pixels << " | " << num(m.coverage, 3) << " | " << num(100 * m.d1_all, 2)
      << " % | " << num(100 * m.d1_estimated, 2) << " % | " << num(m.disparity_mae_px, 2) << " | "
      << num(m.mae_m, 3) << " | " << num(m.rmse_m, 3) << " |\n";
  };
  for (const auto& [method, scores] : depth) {
    row(method, scores.all);
    if (scores.has_split) {
      row(method + " (background)", scores.background);
      row(method + " (foreground)", scores.foreground);
    }
  }
  s << "\n";
  if (depth.count("paper"))
    s << kPaperRows << "\n\n";
}

/// report.md's mesh against the true surface: accuracy, completeness by view distance, the weight curve.
void writeMeshAccuracy(std::ostream& s, const MeshAccuracy& m) {
  s << "## Mesh against the true surface\n\n"
    << "Accuracy (mean distance of " << m.vertices << " mesh vertices to the true surface, capped at "
    << num(m.cap_m) << " m): " << num(m.accuracy_mean_m, 3) << " m (median " << num(m.accuracy_median_m, 3)
    << " m); " << num(100 * m.precision, 1) << " % of vertices within " << num(m.threshold_m) << " m.\n"
    << "Completeness (share of " << m.truth_samples << " samples of the seen true surface within "
    << num(m.threshold_m) << " m of the mesh): " << num(100 * m.completeness, 1) << " %.\n";
  if (!m.by_view_distance.empty()) {
    s << "By the nearest distance a frame saw the surface from:";
    for (const auto& b : m.by_view_distance)
      s << (&b == &m.by_view_distance.front() ? " " : ", ") << num(b.lower_m) << "–" << num(b.upper_m) << " m "
        << num(100 * b.completeness, 1) << " % ("
        << num(100.0 * b.samples / std::max<std::size_t>(1, m.truth_samples), 1) << " % of the samples)";
    s << ".\n";
  }
  if (!m.by_weight.empty()) {
    s << "\nKept at a bar on the vertices' weights (m^-2; the triangles whose three vertices weigh at least it):\n\n"
         "| bar | vertices | accuracy m | completeness |\n|---|---|---|---|\n";
    for (double bar : kWeightBars) {
      const WeightLevel l = m.by_weight.atWeight(bar);
      s << "| " << num(bar) << " | " << l.vertices << " | " << num(l.accuracy_mean_m, 3) << " | "
        << num(100 * l.completeness, 1) << " % |\n";
    }
  }
  s << "\n";
}

/// The optional columns of protocol 4's tables: those some row has a figure for.
struct ScoreColumns {
  bool accuracy = false, ghosts = false, seen = false;
};

ScoreColumns scoreColumns(const RunReport::MapEvaluation& e) {
  ScoreColumns c;
  for (const auto& r : e.rows)
    c.accuracy |= r.has_accuracy, c.ghosts |= r.has_ghosts, c.seen |= r.has_seen_through;
  return c;
}

/// Protocol 4's opening paragraph: what the ground truth is and how the meshes are scored.
void writeEvaluationIntro(std::ostream& s, const RunReport::MapEvaluation& e) {
  s << "## The map against ground truth it never saw (evaluation protocol 4)\n\n"
    << "Ground truth: " << e.truth << ", " << e.gt_pixels << " pixels in " << e.frames
    << " frames. Each mesh is rendered into camera 0 at every frame's pose (the first surface along each pixel's ray) "
       "and scored at the ground-truth pixels beside the per-frame fused depth; a missing estimate counts as bad in "
       "D1. Within range: true depth at most "
    << num(e.range_m)
    << " m (`tsdf_integrator.max_depth_m`, at most the depth of `rig.stereo_min_disparity_px`), the map holds nothing "
       "farther."
    << (e.moving_split ? " Pixels on moving objects are scored apart: a moving object is not part of the map." : "")
    << "\n\n";
}

/// One table of protocol 4: a row per source, its pixels in range and all of them, and the optional columns.
void writeScoreTable(std::ostream& s, const RunReport::MapEvaluation& e, const ScoreColumns& c, const char* what,
                     DepthMetrics ReconstructionScore::*in_range, DepthMetrics ReconstructionScore::*all) {
  s << "| " << what
    << " | pixels in range | coverage | D1 | D1 on estimates | MAE m | pixels | coverage | D1 | MAE m |"
    << (c.accuracy ? " accuracy m | completeness |" : "") << (c.ghosts ? " ghosts | crumbs | specks |" : "")
    << (c.seen ? " pieces seen through |" : "") << "\n|---|---|---|---|---|---|---|---|---|---|"
    << (c.accuracy ? "---|---|" : "") << (c.ghosts ? "---|---|---|" : "") << (c.seen ? "---|" : "") << "\n";
  for (const auto& r : e.rows) {
    const DepthMetrics &a = r.score.*in_range, &b = r.score.*all;
    s << "| " << r.score.source << " | " << a.gt_pixels << " | " << num(a.coverage, 3) << " | "
      << num(100 * a.d1_all, 2) << " % | " << num(100 * a.d1_estimated, 2) << " % | " << num(a.mae_m, 3) << " | "
      << b.gt_pixels << " | " << num(b.coverage, 3) << " | " << num(100 * b.d1_all, 2) << " % | " << num(b.mae_m, 3)
      << " |";
    if (c.accuracy)
      s << (r.has_accuracy ? " " + num(r.accuracy.accuracy_mean_m, 3) + " | " + num(100 * r.accuracy.completeness, 1) +
                                 " % |"
                           : " | |");
    if (c.ghosts)
      s << (r.has_ghosts ? " " + num(100 * r.ghosts.share, 3) + " % | " + crumbsCell(r.crumbs) + " | " +
                               std::to_string(r.crumbs.specks) + " |"
                         : " | | |");
    if (c.seen)
      s << (r.has_seen_through ? " " + std::to_string(r.seen_through.seen_through) + " |" : " |");
    s << "\n";
  }
  s << "\n";
}

/// The static pixels within range split by the scans: a surface that stayed, and one that left.
void writeTransientTable(std::ostream& s, const RunReport::MapEvaluation& e) {
  if (!e.transient_split)
    return;
  s << "Within range, split by the scans: transient where the scan of a frame up to "
    << ReconstructionEvaluation::kScanWindow
    << " before or after saw through the true return (its returns around that direction lie a D1 outlier behind it, "
       "beyond the sweep's skew), as on the places a vehicle ahead left; a map of what stays need not hold those.\n\n"
       "| source | lasting pixels | coverage | D1 | MAE m | transient pixels | coverage | D1 | MAE m |\n"
       "|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : e.rows) {
    const DepthMetrics &a = r.score.lasting_within_range, &b = r.score.transient_within_range;
    s << "| " << r.score.source << " | " << a.gt_pixels << " | " << num(a.coverage, 4) << " | "
      << num(100 * a.d1_all, 2) << " % | " << num(a.mae_m, 3) << " | " << b.gt_pixels << " | "
      << num(b.coverage, 4) << " | " << num(100 * b.d1_all, 2) << " % | " << num(b.mae_m, 3) << " |\n";
  }
  s << "\n";
}

/// The fused mesh kept at the weight bar that matches each other mesh's completeness (when it has a curve).
void writeFusedAtCompleteness(std::ostream& s, const RunReport::MapEvaluation& e) {
  const RunReport::MapEvaluation::Row* fused = e.fusedCurveRow();
  if (!fused)
    return;
  std::string rows;
  for (const auto& other : e.rows)
    if (&other != fused && other.has_accuracy) {
      const WeightLevel l = fused->accuracy.by_weight.atCompleteness(other.accuracy.completeness);
      rows += "| " + other.score.source + " | " + num(100 * other.accuracy.completeness, 1) + " % | " +
              num(other.accuracy.accuracy_mean_m, 3) + " | " + num(l.min_weight, 1) + " | " +
              num(100 * l.completeness, 1) + " % | " + num(l.accuracy_mean_m, 3) + " |\n";
    }
  if (!rows.empty())
    s << "\nThe fused mesh kept at a bar on its vertices' weights (its surest surface), at the completeness of each "
         "other mesh:\n\n| other mesh | its completeness | its accuracy m | fused mesh's bar m^-2 | completeness | "
         "accuracy m |\n|---|---|---|---|---|---|\n"
      << rows << "\n";
}

/// What the brackets of the crumbs' column say, for `buckets` buckets of their ages (none: "").
std::string crumbAgesNote(std::size_t buckets) {
  if (buckets == 0)
    return "";
  std::string ages;
  for (std::size_t i = 1; i <= buckets; ++i)
    ages += (i > 1 ? " / " : "") + std::to_string(i);
  return "; in brackets, the crumbs whose place the object left " + ages +
         (buckets > 1 ? " or more" : "") +
         " frames before the last one (a place left a frame ago has been looked through by one frame at most)";
}

/// What the ghost, crumb and seen-through columns count (or why there is no ghost figure).
void writeGhostNotes(std::ostream& s, const RunReport::MapEvaluation& e, const ScoreColumns& c) {
  if (!e.no_ghosts.empty())
    s << "No ghost figure: " << e.no_ghosts << ".\n";
  else if (c.ghosts)
    s << "Ghosts: share of the mesh's vertices farther than " << num(e.rows.front().ghosts.distance_m)
      << " m from the static true surface inside the space a moving object occupied and had left by the last "
         "frame; crumbs (specks): pieces of fewer than "
      << e.rows.front().crumbs.max_triangles
      << " triangles mostly that far from it, inside that space (elsewhere)"
      << crumbAgesNote(e.rows.front().crumbs.by_frames_since_left.size()) << ".\n";
  if (c.seen)
    s << "Pieces seen through: pieces of fewer than " << e.rows.front().seen_through.max_triangles
      << " triangles most of whose vertices lie in front of the true depth by more than D1's threshold at some "
         "frame: the ground truth saw through them.\n";
}

} // namespace

double peakMemoryMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0; // ru_maxrss is in KiB on Linux
}

double residentMemoryMb() {
  std::ifstream statm("/proc/self/statm");
  double pages_total = 0, pages_resident = 0;
  if (!(statm >> pages_total >> pages_resident))
    return 0.0;
  return pages_resident * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

const RunReport::MapEvaluation::Row* RunReport::MapEvaluation::fusedCurveRow() const {
  for (const auto& r : rows)
    if (r.score.source == "mesh" && r.has_accuracy && !r.accuracy.by_weight.empty())
      return &r;
  return nullptr;
}

double RunReport::framesPerSecond() const {
  return wall_s > 0 ? static_cast<double>(frames.size()) / wall_s : 0.0;
}

double RunReport::framesPerSecondAfterFirst() const {
  const double span = wall_s - first_frame_s;
  return frames.size() > 1 && span > 0 ? static_cast<double>(frames.size() - 1) / span : 0.0;
}

std::vector<double> RunReport::lidarStereoDisagreements() const {
  std::vector<double> shares;
  for (const FrameRow& r : frames)
    shares.push_back(r.lidar_stereo_disagreement);
  return shares;
}

void RunReport::writeFramesCsv(const std::string& path) const {
  std::ostringstream s;
  s << "frame,name";
  for (const auto& c : stageColumns())
    s << "," << c.name << "_ms";
  s << ",rss_mb,lidar_stereo_disagreement\n";
  for (const auto& r : frames) {
    s << r.index << "," << r.name;
    for (const auto& c : stageColumns())
      s << "," << num(c.get(r), 3);
    s << "," << num(r.rss_mb, 1) << "," << num(r.lidar_stereo_disagreement, 4) << "\n";
  }
  writeText(path, s.str());
}

void RunReport::writeSummaryJson(const std::string& path) const {
  std::ostringstream s;
  s << "{\n"
    << "  \"msfusion\": {\"version\": " << jsonString(versionString()) << ", \"commit\": " << jsonString(gitCommit())
    << "},\n"
    << "  \"dataset\": " << jsonString(dataset) << ",\n"
    << "  \"layout\": " << jsonString(layout) << ",\n";
  writeTrajectoryJson(s);
  writeSpeedJson(s);
  writeMapJson(s);
  s << "  \"reconstruction_evaluation\": " << mapEvaluationJson(map_evaluation) << ",\n"
    << "  \"open_sky\": " << openSkyJson(open_sky) << ",\n"
    << "  \"config\": " << (config_yaml.empty() ? "null" : configJson(config_yaml)) << "\n}\n";
  writeText(path, s.str());
}

void RunReport::writeTrajectoryJson(std::ostream& s) const {
  s << "  \"trajectory\": {\"source\": " << jsonString(trajectory) << ", \"file\": " << jsonString(poses_file);
  if (!pose_ms.empty())
    s << ", \"estimate_ms\": {\"median\": " << num(median(pose_ms), 3)
      << ", \"p95\": " << num(percentile(pose_ms, 95), 3) << "}";
  if (has_trajectory_metrics) {
    const OdometryMetrics& m = trajectory_metrics;
    s << ", \"reference\": " << jsonString(trajectory_reference) << ", \"ate_rmse_m\": " << num(m.ate_rmse_m, 4)
      << ", \"end_drift_m\": " << num(m.end_drift_m, 4) << ", \"end_drift_pct\": " << num(m.end_drift_pct, 3)
      << ", \"translation_error_pct\": " << num(m.translation_error_pct, 3)
      << ", \"rotation_error_deg_per_m\": " << num(m.rotation_error_deg_per_m, 5);
  }
  s << "},\n";
}

void RunReport::writeSpeedJson(std::ostream& s) const {
  s << "  \"frames\": " << frames.size() << ",\n"
    << "  \"frames_requested\": " << frames_requested << ",\n"
    << "  \"interrupted\": " << (interrupted ? "true" : "false") << ",\n"
    << "  \"skipped\": [";
  for (std::size_t k = 0; k < skipped.size(); ++k)
    s << (k ? ", " : "") << jsonString(skipped[k]);
  s << "],\n"
    << "  \"wall_s\": " << num(wall_s, 3) << ",\n"
    << "  \"frames_per_second\": " << num(framesPerSecond(), 3) << ",\n"
    << "  \"first_frame_s\": " << num(first_frame_s, 3) << ",\n"
    << "  \"frames_per_second_after_first\": " << num(framesPerSecondAfterFirst(), 3) << ",\n"
    << "  \"peak_memory_mb\": " << num(peakMemoryMb() > peak_memory_mb ? peakMemoryMb() : peak_memory_mb, 1)
    << ",\n"
    << "  \"predicted_memory_mb\": " << (predicted_memory_mb >= 0 ? num(predicted_memory_mb, 1) : std::string("null"))
    << ",\n"
    << "  \"lidar_stereo_disagreement\": " << num(medianDisagreement(lidarStereoDisagreements()), 4) << ",\n"
    << "  \"stage_ms\": {\n";
  const auto& columns = stageColumns();
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const auto values = column(frames, columns[k]);
    s << "    \"" << columns[k].name << "\": {\"median\": " << num(median(values), 3)
      << ", \"p95\": " << num(percentile(values, 95), 3) << "}" << (k + 1 < columns.size() ? "," : "") << "\n";
  }
  s << "  },\n"
    << "  \"mesh_ms\": " << num(mesh_ms, 3) << ",\n";
}

void RunReport::writeMapJson(std::ostream& s) const {
  s << "  \"map\": {\"voxel_size_m\": " << num(voxel_size_m) << ", \"lambda\": " << num(lambda)
    << ", \"observed_voxels\": " << observed_voxels << ", \"blocks\": " << blocks
    << ", \"memory_mb\": " << num(volume_memory_mb, 1) << ", \"vertices\": " << vertices
    << ", \"triangles\": " << triangles << ", \"pieces_removed\": " << pieces_removed
    << ", \"triangles_removed\": " << triangles_removed << "},\n"
    << "  \"depth\": " << depthJson(depth) << ",\n"
    << "  \"mesh_accuracy\": " << (has_mesh_accuracy ? accuracyJson(mesh_accuracy) : "null") << ",\n";
}

void RunReport::writeRuntimePlot(const std::string& path) const {
  LinePlot plot("Run time per frame (" + std::to_string(frames.size()) + " frames, " + num(framesPerSecond(), 1) +
                    " fps end to end)",
                "frame", "milliseconds");
  std::vector<double> x;
  for (const auto& r : frames)
    x.push_back(static_cast<double>(r.index));
  for (const auto& c : stageColumns())
    if (std::string(c.name) != "depth")
      plot.addSeries(c.name, x, column(frames, c));
  plot.addReferenceLine(100.0, "100 ms = 10 Hz");
  writeImage(path, plot.render(1000, 520));
}

void RunReport::writeMarkdown(const std::string& path) const {
  std::ostringstream s;
  writeIntro(s);
  writeSpeed(s);
  writeMapSize(s);
  if (!depth.empty())
    writeDepthTable(s, depth);
  if (has_mesh_accuracy)
    writeMeshAccuracy(s, mesh_accuracy);
  if (!map_evaluation.rows.empty())
    writeMapEvaluation(s);
  if (!open_sky.empty())
    writeOpenSky(s);
  writeTruthOffSurface(s);
  writeDepthImagesAndLinks(s);
  writeText(path, s.str());
}

void RunReport::writeIntro(std::ostream& s) const {
  s << "# msfusion reconstruction\n\n"
    << "Dataset `" << dataset << "` (" << layout << "), " << frames.size() << " of " << frames_requested
    << " frames" << (interrupted ? " (interrupted: the map holds the frames integrated before the stop)" : "")
    << "." << skippedSentence(skipped) << " Voxel " << num(voxel_size_m) << " m, lambda " << num(lambda) << ".\n\n"
    << "Trajectory: " << trajectory << ", [`" << poses_file << "`](" << poses_file << ")";
  if (!pose_ms.empty())
    s << "; the odometry took " << num(median(pose_ms), 1) << " ms per frame (median, p95 "
      << num(percentile(pose_ms, 95), 1) << ") on its own thread";
  s << ".";
  if (has_trajectory_metrics) {
    const OdometryMetrics& m = trajectory_metrics;
    s << " Against " << trajectory_reference << " (protocol 5, first poses aligned): ATE " << num(m.ate_rmse_m, 3)
      << " m RMSE, end-point drift " << num(m.end_drift_m, 3) << " m = " << num(m.end_drift_pct, 2) << " % of "
      << num(m.path_length_m, 1) << " m, devkit translation error " << num(m.translation_error_pct, 2)
      << " %, rotation " << num(m.rotation_error_deg_per_m, 4) << " deg/m.";
  }
  s << "\n\n";
  if (!trajectory_plot_file.empty())
    s << "![the trajectory from above](" << trajectory_plot_file << ")\n\n";
}

void RunReport::writeSpeed(std::ostream& s) const {
  s << "## Speed\n\n"
    << num(framesPerSecond(), 2) << " frames per second end to end (" << num(wall_s, 2) << " s; "
    << num(framesPerSecondAfterFirst(), 2) << " after the first frame, done at " << num(first_frame_s, 2)
    << " s), peak memory " << num(std::max(peak_memory_mb, peakMemoryMb()), 0) << " MiB, mesh extraction "
    << num(mesh_ms, 1) << " ms.\n\n"
    << "| stage | median ms | p95 ms |\n|---|---|---|\n";
  for (const auto& c : stageColumns()) {
    const auto values = column(frames, c);
    s << "| " << c.name << " | " << num(median(values), 1) << " | " << num(percentile(values, 95), 1) << " |\n";
  }
  s << "\nLiDAR and stereo run at the same time (`depth` is their wall time); loading, depth and "
       "integration of successive frames overlap, so frames per second exceed 1000 / latency.\n\n"
    << "![run time per frame](runtime.png)\n\n";
}

void RunReport::writeMapSize(std::ostream& s) const {
  s << "## Map\n\n"
    << observed_voxels << " observed voxels in " << blocks << " blocks (" << num(volume_memory_mb, 1) << " MiB); mesh "
    << vertices << " vertices, " << triangles << " triangles: [`" << mesh_file << "`](" << mesh_file << "), volume [`"
    << volume_file << "`](" << volume_file << ").";
  if (pieces_removed > 0)
    s << " " << pieces_removed << " pieces of fewer than `marching_cubes.min_component_triangles` triangles that no "
      << "vertex of `marching_cubes.component_keep_weight` holds, or closed within "
      << "`marching_cubes.min_component_extent_voxels` (" << triangles_removed << " triangles), were removed.";
  s << "\n\n";
  if (!preview_file.empty())
    s << "![mesh from above and from the first camera](" << preview_file << ")\n\n";
}

void RunReport::writeDepthImagesAndLinks(std::ostream& s) const {
  if (!depth_panels.empty()) {
    s << "## Depth images\n\nRows: left image, projected LiDAR, interpolated LiDAR, SGBM, fused"
         " (and the fused depth's error where ground truth exists).\n\n";
    for (const auto& panel : depth_panels)
      s << "![" << panel << "](" << panel << ")\n\n";
  }
  s << "Per-frame times: [`frames.csv`](frames.csv); all figures: [`summary.json`](summary.json)";
  if (!config_file.empty())
    s << "; the configuration in full: [`" << config_file << "`](" << config_file << ")";
  s << ".\n";
}

void RunReport::writeClassTable(std::ostream& s) const {
  std::vector<const MapEvaluation::Row*> rows;
  for (const auto& r : map_evaluation.rows)
    if (r.has_accuracy && !r.accuracy.by_class.empty())
      rows.push_back(&r);
  if (rows.empty())
    return;
  s << "\nBy the class of the nearest true surface: the share of each mesh's vertices there, their mean distance, "
       "their part of the mesh's accuracy (the parts add up to it) and the class's completeness ("
    << ClassAccuracy::kOffSurface << ": vertices no true surface is within the cap of):\n\n| class |";
  for (const auto* r : rows)
    s << " " << r->score.source << " vertices | accuracy m | part m | completeness |";
  s << "\n|---|";
  for (std::size_t k = 0; k < rows.size(); ++k)
    s << "---|---|---|---|";
  s << "\n";
  std::vector<std::string> names; // every row's classes, in order of first appearance
  for (const auto* r : rows)
    for (const auto& a : r->accuracy.by_class)
      if (std::find(names.begin(), names.end(), a.name) == names.end())
        names.push_back(a.name);
  for (const std::string& name : names) {
    s << "| " << name << " |";
    for (const auto* r : rows) {
      const auto& split = r->accuracy.by_class;
      const auto it = std::find_if(split.begin(), split.end(), [&](const ClassAccuracy& a) { return a.name == name; });
      if (it == split.end()) {
        s << " | | | |";
        continue;
      }
      const double share = static_cast<double>(it->vertices) / static_cast<double>(std::max<std::size_t>(1, r->accuracy.vertices));
      s << " " << num(100 * share, 1) << " % | " << num(it->accuracy_mean_m, 3) << " | " << num(it->contribution_m, 4)
        << " | " << (it->truth_samples ? num(100 * it->completeness, 1) + " %" : std::string("")) << " |";
    }
    s << "\n";
  }
  s << "\n";
}

void RunReport::writeOpenSky(std::ostream& s) const {
  s << "## The open sky (evaluation protocol 6)\n\n"
    << "Each frame's open sky: bright, blank (grey standard deviation over 5x5 pixels), grey-white or blue pixels "
       "above the highest LiDAR return of their columns, connected to the image's top edge, less a 3-pixel border "
       "(msf::SkyMask). Each mesh rendered at every frame's pose should leave them empty; the share it covers:\n\n"
    << "| mesh | frames | sky pixels | covered | mean per frame | worst frame | median depth of the cover |\n"
    << "|---|---|---|---|---|---|---|\n";
  for (const auto& [name, c] : open_sky)
    s << "| " << name << " | " << c.frames << " | " << c.sky_pixels << " | " << num(100 * c.share, 2) << " % | "
      << num(100 * c.mean_frame_share, 2) << " % | " << num(100 * c.worst_share, 2) << " % (frame " << c.worst_frame
      << ") | " << (c.covered_pixels > 0 ? num(c.covered_depth_median_m, 1) + " m" : std::string("none")) << " |\n";
  s << "\n";
  if (!sky_pictures.empty())
    s << "The sky in cyan, where the mesh covers it in red:\n\n";
  for (const auto& picture : sky_pictures)
    s << "![" << picture << "](" << picture << ")\n\n";
}

void RunReport::writeTruthOffSurface(std::ostream& s) const {
  std::vector<const MapEvaluation::Row*> rows;
  for (const auto& r : map_evaluation.rows)
    if (r.has_accuracy)
      rows.push_back(&r);
  if (rows.empty())
    return;
  const double off_m = rows.front()->off_surface.distance_m;
  const auto share = [](const SkyCoverage& c) {
    return num(100 * c.share, 2) + " % | " + num(100 * c.mean_frame_share, 2) + " % | " + num(100 * c.worst_share, 2) +
           " % (frame " + std::to_string(c.worst_frame) + ")";
  };
  s << "## The true sky and the surface off the truth (synthetic)\n\n"
    << "The true sky (pixels of zero true depth, less protocol 6's 3-pixel border) that each mesh rendered at every "
       "frame's pose covers; a sheet: the covering surface lies farther than "
    << num(off_m) << " m from the static true surface (a blurred outline lies nearer):\n\n"
    << "| mesh | sky pixels | covered | mean per frame | worst frame | by sheets | mean per frame | worst frame |\n"
    << "|---|---|---|---|---|---|---|---|\n";
  for (const auto* r : rows)
    s << "| " << r->score.source << " | " << r->true_sky.sky_pixels << " | " << share(r->true_sky) << " | "
      << share(r->true_sky_sheets) << " |\n";
  s << "\nThe mesh's area farther than " << num(off_m)
    << " m from the static true surface (gt/scene.ply; a moving car's ghost is off it too), by height above the road "
       "and whether a LiDAR return of any frame lay within a cell (a voxel) of it, as shares of that area:\n\n"
       "| mesh | area m² | off the surface |";
  const auto& bands = rows.front()->off_surface.bands;
  for (const auto& b : bands)
    s << " " << bandText(b) << ", LiDAR | " << bandText(b) << ", none |";
  s << "\n|---|---|---|";
  for (std::size_t k = 0; k < bands.size(); ++k)
    s << "---|---|";
  s << "\n";
  for (const auto* r : rows) {
    const OffSurfaceSplit& o = r->off_surface;
    s << "| " << r->score.source << " | " << num(o.area_m2, 1) << " | " << num(o.off_area_m2, 2) << " m² ("
      << num(100 * o.offShare(), 2) << " %) |";
    for (const auto& b : o.bands)
      s << " " << num(100 * o.shareOfOff(b.supported_m2), 1) << " % | " << num(100 * o.shareOfOff(b.unsupported_m2), 1)
        << " % |";
    s << "\n";
  }
  s << "\n";
}

void RunReport::writeMapEvaluation(std::ostream& s) const {
  const MapEvaluation& e = map_evaluation;
  writeEvaluationIntro(s, e);
  const ScoreColumns columns = scoreColumns(e);
  writeScoreTable(s, e, columns, e.moving_split ? "source (static pixels)" : "source",
                  &ReconstructionScore::within_range, &ReconstructionScore::all);
  if (e.moving_split)
    writeScoreTable(s, e, columns, "source (moving objects)", &ReconstructionScore::moving_within_range,
                    &ReconstructionScore::moving_all);
  writeTransientTable(s, e);
  for (const auto& r : e.rows)
    if (r.score.source == "paper") {
      s << kPaperRows << "\n";
      break;
    }
  if (columns.accuracy)
    s << "Accuracy: mean distance of the mesh's vertices to the true surface; completeness: share of the seen true "
         "surface within the threshold of the mesh (as above).\n";
  writeFusedAtCompleteness(s, e);
  writeClassTable(s);
  writeGhostNotes(s, e, columns);
  s << "\n";
}

} // namespace msf
