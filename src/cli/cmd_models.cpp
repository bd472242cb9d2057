// posebench models [--registry FILE] [--write DIR]: lists the registry (name,
// id, source, size, diameter, symmetries, availability) and writes the
// project's generated models as PLY meshes (mm) for viewers and other tools.
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli/command.h"
#include "io/mesh_io.h"
#include "models/registry.h"

namespace fs = std::filesystem;

static pb::cli::Command models_cmd("models", "list the model registry; write the generated models as PLY", [](int argc, char** argv) {
  CLI::App app{"Lists every model of the registry with its size and symmetries, and whether its mesh "
               "is available. --write DIR writes each generated model as DIR/NAME.ply (mm)."};
  std::string registry, write_dir;
  bool all = false;
  app.add_option("--registry", registry, "registry file (default: models/models.yaml)");
  app.add_option("--write", write_dir, "write the generated models as PLY into this folder");
  app.add_flag("--all", all, "with --write: also the available shared models (normalized, mm)");
  PB_CLI_PARSE(app, argc, argv);
  const pb::ModelRegistry reg = registry.empty() ? pb::ModelRegistry::load_default() : pb::ModelRegistry::load(registry);
  if (!write_dir.empty()) fs::create_directories(write_dir);
  std::printf("%-18s %4s  %-28s %-22s %9s  %s\n", "name", "id", "source", "size (mm)", "diam (mm)", "symmetries");
  int missing = 0, written = 0;
  for (const auto& name : reg.names()) {
    const pb::ModelSpec& spec = reg.spec(name);
    std::string why;
    if (!reg.available(name, &why)) {
      ++missing;
      std::printf("%-18s %4d  %-28s unavailable: %s\n", name.c_str(), spec.obj_id, spec.source.c_str(), why.c_str());
      continue;
    }
    const pb::Mesh mesh = reg.load_model(name);
    const pb::ModelInfo info = reg.info(name, mesh);
    char size[64];
    std::snprintf(size, sizeof size, "%.0f x %.0f x %.0f", info.size.x(), info.size.y(), info.size.z());
    std::string sym;
    if (!info.symmetries_continuous.empty()) sym += std::to_string(info.symmetries_continuous.size()) + " continuous";
    if (!info.symmetries_discrete.empty())
      sym += (sym.empty() ? "" : ", ") + std::to_string(info.symmetries_discrete.size()) + " discrete";
    std::printf("%-18s %4d  %-28s %-22s %9.1f  %s\n", name.c_str(), spec.obj_id, spec.source.c_str(), size,
                info.diameter, sym.empty() ? "none" : sym.c_str());
    const bool generated = spec.source.rfind("generated:", 0) == 0;
    if (!write_dir.empty() && (generated || all)) {
      pb::write_ply((fs::path(write_dir) / (name + ".ply")).string(), mesh);
      ++written;
    }
  }
  if (!write_dir.empty()) std::cout << "wrote " << written << " meshes to " << write_dir << "\n";
  if (missing) std::cout << missing << " model(s) unavailable (their experiments are skipped)\n";
  return 0;
});
