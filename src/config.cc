#include "finecap/config.h"

#include "finecap/error.h"

namespace finecap {

void Config::Check() const { frame_range(); }

ConfigSchema MakeConfigSchema(Config* config) {
  ConfigSchema schema;
  schema.AddString("capture.dir", &config->capture.dir,
                   "Capture folder (cameras, images or videos, meshes; see the README).");
  schema.AddString("capture.frames", &config->capture.frames,
                   "Frames to process: \"A:B\" = indices A..B-1 of the sorted frame list; "
                   "\"\" = all.");
  schema.AddString("output.dir", &config->output.dir,
                   "Output folder; created if missing; existing files are never overwritten.");
  schema.AddChoice("output.mesh_format", &config->output.mesh_format,
                   "Format of refined meshes (PLY is binary).", {"ply", "obj"});
  schema.AddInt("runtime.threads", &config->runtime.threads,
                "Worker threads for parallel stages; 0 = all cores.", 0, 1024);
  return schema;
}

Config LoadConfig(const std::string& file, const std::vector<ConfigOverride>& overrides) {
  Config config;
  ConfigSchema schema = MakeConfigSchema(&config);
  if (!file.empty()) schema.ReadFile(file);
  for (const ConfigOverride& override_value : overrides) {
    schema.Set(override_value.key, override_value.value, override_value.source);
  }
  try {
    config.Check();
  } catch (const Error& error) {
    throw Error(file.empty() ? "config" : file, error.what());
  }
  return config;
}

}  // namespace finecap
