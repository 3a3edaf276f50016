// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The configuration: a file checked and printed in full, and the files made from the keys'
// declarations (config/*.yaml, docs/configuration.md) written.
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/pipeline/config_documents.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

namespace {

/// What -write makes: config/<name>.yaml for each shipped configuration and
/// docs/configuration.md under `root` (the repository), with their texts.
std::vector<std::pair<std::string, std::string>> documents(const std::string& root) {
  std::vector<std::pair<std::string, std::string>> files;
  for (const std::string& name : msf::shippedConfigNames())
    files.emplace_back(root + "/config/" + name + ".yaml", msf::shippedConfigText(name));
  files.emplace_back(root + "/docs/configuration.md", msf::configurationReference());
  return files;
}

/// Whether `path` is a file -write made: each names the command that makes it.
bool madeByWrite(const std::string& path) {
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return text.find("make config-files") != std::string::npos;
}

/// Writes the documents, after checking that root's config/ and docs/ folders exist and that
/// every file to be replaced is one -write made: a file of the user's under the same name is
/// refused, and nothing is written.
void writeDocuments(const std::string& root) {
  msf::requireDirectory(root + "/config", "-write's config folder");
  msf::requireDirectory(root + "/docs", "-write's docs folder");
  const auto files = documents(root);
  for (const auto& [path, text] : files)
    if (std::filesystem::exists(path) && !madeByWrite(path))
      throw msf::IOError("'" + path + "' is not a file msf_config -write made (it does not name make config-files): "
                         "-write writes into the repository only; nothing was written");
  for (const auto& [path, text] : files) {
    msf::writeStreamAtomically(path, [&text = text](std::ostream& out) { out << text; });
    std::cout << "wrote " << path << "\n";
  }
}

} // namespace

int main(int argc, char** argv) {
  std::string config_path, write_root;
  bool paper = false, comments = false;
  msf::tool::CommandLine cli(
      "msf_config", "[options]",
      "Prints the configuration msf_reconstruct runs with, every key of every section as a YAML file that "
      "-config reads back (and PyYAML reads): the defaults, the paper as published, or what a file gives. A file "
      "is checked whole, as every tool checks it: a section or key the project does not know, a key written twice, "
      "a value of the wrong type or out of its range is an error naming the file, the line and the key.");
  cli.value("-config", "FILE", config_path, "a YAML configuration, over the defaults (or over -paper's)")
      .flag("-paper", paper, "start from the paper as published (config/paper.yaml) instead of the defaults")
      .flag("-comments", comments, "each key's meaning and range as a comment above it")
      .value("-write", "DIR",
             write_root,
             "write DIR/config/kitti.yaml, synthetic.yaml, paper.yaml and DIR/docs/configuration.md, made from the "
             "keys' declarations (DIR: the repository; make config-files); a file there that -write did not make is "
             "refused");
  return cli.run(argc, argv, 0, [&](const msf::tool::Arguments& arguments) {
    if (!arguments.empty())
      throw msf::InvalidInputError("unexpected argument '" + arguments[0] + "' (see -h)");
    if (!write_root.empty()) {
      if (paper || comments || !config_path.empty())
        throw msf::InvalidInputError("-write writes the files made from the declarations alone: no other option");
      writeDocuments(write_root);
      return 0;
    }
    msf::PipelineConfig config = paper ? msf::PipelineConfig::paper() : msf::PipelineConfig{};
    if (!config_path.empty())
      config.read(msf::openConfigFile(config_path));
    msf::PipelineConfig::forEachSection(config, [&](const auto& section) {
      if (comments)
        msf::printComment(std::cout, "", section.kAbout);
      msf::printSection(std::cout, section.kSection, msf::listKeys(section), comments);
    });
    return 0;
  });
}
