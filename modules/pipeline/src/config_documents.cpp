// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/pipeline/config_documents.h>

#include <sstream>

namespace msf {

namespace {

const char* const kHowToRead =
    "One section per stage, a map of its keys; a key absent from a file keeps its default. Units are in the key "
    "names, a key's range or words in brackets. Every tool takes -config FILE, and flags that override single "
    "keys. Made from the keys' declarations in the code (make config-files); docs/configuration.md lists them.";

/// Every section (its default Config) whose name `keep` accepts, with its comments.
template <class Keep>
std::string defaultsFile(const std::string& header, Keep&& keep) {
  std::ostringstream out;
  printComment(out, "", header);
  printComment(out, "", kHowToRead);
  forEachConfigSection([&](const auto& config) {
    if (!keep(std::string(config.kSection)))
      return;
    out << "\n";
    printComment(out, "", config.kAbout);
    printSection(out, config.kSection, listKeys(config), true);
  });
  return out.str();
}

/// The keys of PipelineConfig::paper() whose value differs from the default, with their comments.
std::string paperFile() {
  std::ostringstream out;
  printComment(out, "",
               "The paper as published: Ali, Rajput et al., \"Multi-Sensor Depth Fusion Framework for Real-Time 3D "
               "Reconstruction\", IEEE Access 7 (2019) 136471, without the project's additions. Every key absent "
               "here keeps its default (config/kitti.yaml); each key below switches an addition off, and "
               "docs/paper.md measures what each adds. PipelineConfig::paper() is this configuration in code, and "
               "this file is made from it (make config-files); msf_holdout's `paper` row and msf_reconstruct "
               "-compare_paper run it:");
  out << "#   build/bin/msf_reconstruct ../shared/data/kitti/odometry/sequences/04 -config config/paper.yaml\n";
  const PipelineConfig ours, paper = PipelineConfig::paper();
  std::vector<std::vector<KeyText>> defaults;
  PipelineConfig::forEachSection(ours, [&](const auto& config) { defaults.push_back(listKeys(config)); });
  std::size_t index = 0;
  PipelineConfig::forEachSection(paper, [&](const auto& config) {
    const std::vector<KeyText> keys = listKeys(config), default_keys = defaults[index++];
    std::vector<KeyText> changed;
    for (std::size_t k = 0; k < keys.size(); ++k)
      if (keys[k].value != default_keys[k].value)
        changed.push_back(keys[k]);
    if (changed.empty())
      return;
    out << "\n";
    printComment(out, "", config.kAbout);
    printSection(out, config.kSection, changed, true);
  });
  return out.str();
}

/// `text` in a Markdown table cell.
std::string cell(const std::string& text) {
  std::string escaped;
  for (const char c : text)
    escaped += c == '|' ? std::string("\\|") : std::string(1, c);
  return escaped;
}

} // namespace

std::vector<std::string> shippedConfigNames() { return {"kitti", "synthetic", "paper"}; }

std::string shippedConfigText(const std::string& name) {
  if (name == "kitti")
    return defaultsFile("msfusion's configuration for KITTI (odometry sequences and raw drives): every key of every "
                        "stage at its default, which a run without -config uses.",
                        [](const std::string& section) { return section != "synthetic" && section != "lambda_study"; });
  if (name == "synthetic")
    return defaultsFile("msfusion's configuration for the synthetic street: the generator's section (msf_synth; a "
                        "dataset keeps its own in gt/synthetic.yaml), every key of every stage at its default, and "
                        "the lambda study's (msf_lambda_study).",
                        [](const std::string&) { return true; });
  if (name == "paper")
    return paperFile();
  throw InvalidInputError("no shipped configuration '" + name + "' (kitti, synthetic, paper)");
}

std::string configurationReference() {
  std::ostringstream out;
  out << "# Configuration\n\n"
      << "<!-- Made by `make config-files` from the keys' declarations in the code; a test checks that it is "
         "up to date. -->\n\n"
      << "A configuration file is plain YAML (PyYAML and ROS parameter files read it; OpenCV's `%YAML:1.0` files "
         "read too): one\nsection per stage, each a map of its keys. A key absent from a file keeps its default "
         "below; units are in\nthe key names. `config/kitti.yaml` and `config/synthetic.yaml` hold every key of the "
         "pipeline's stages at its\ndefault (`synthetic.yaml` also the street's, `synthetic` and `lambda_study`), "
         "`config/paper.yaml` the paper as\npublished. A tool given `-config FILE` reads the whole file "
         "and refuses, naming the file, the\nline and the key, a section or key that is not below, a key written "
         "twice, or a value of the wrong type or\nout of its range; `msf_config -config FILE` prints the "
         "configuration a file gives, in full.\n\n"
      << "| section | what it configures |\n|---|---|\n";
  forEachConfigSection(
      [&](const auto& config) { out << "| `" << config.kSection << "` | " << cell(config.kAbout) << " |\n"; });
  out << "\n| section | key | default | range | meaning |\n|---|---|---|---|---|\n";
  forEachConfigSection([&](const auto& config) {
    for (const KeyText& key : listKeys(config))
      out << "| `" << config.kSection << "` | `" << key.name << "` | `" << cell(key.value) << "` | "
          << cell(key.range) << " | " << cell(key.meaning) << " |\n";
  });
  return out.str();
}

} // namespace msf
