// The keys of section `synth`: every field of SynthOptions, named as in configs/synth_*.yaml.
//
// Most keys are plain numbers, flags and choices. Four kinds need their own parsing, done here
// through ConfigSchema::AddCustom: the 64-bit seeds, lists of a fixed length (lens distortion,
// colours, a light direction) and the list of fold families, whose items are mappings.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "finecap/config/config.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

constexpr double kNoMin = std::numeric_limits<double>::lowest();
constexpr double kNoMax = std::numeric_limits<double>::max();

// The schema names a key as "<file>: key '<path>'". A part of a value (a fold's field) goes
// inside the quotes, so that its errors read like those of any other key.
std::string SubKeyWhere(const std::string& where, const std::string& suffix) {
  if (!where.empty() && where.back() == '\'') {
    return where.substr(0, where.size() - 1) + suffix + "'";
  }
  return where + suffix;
}

// The shortest decimal text that reads back as exactly `value` ("0.16", not "0.16000000000000001").
std::string NumberText(double value) {
  for (int precision : {15, std::numeric_limits<double>::max_digits10}) {
    std::ostringstream text;
    text.precision(precision);
    text << value;
    if (std::stod(text.str()) == value) return text.str();
  }
  return YAML::Node(value).as<std::string>();
}

std::string RangeText(double min, double max) {
  if (min == kNoMin && max == kNoMax) return "";
  if (max == kNoMax) return ">= " + NumberText(min);
  if (min == kNoMin) return "<= " + NumberText(max);
  return "[" + NumberText(min) + ", " + NumberText(max) + "]";
}

std::string ListText(const double* values, int size) {
  std::string text = "[";
  for (int i = 0; i < size; ++i) text += (i ? ", " : "") + NumberText(values[i]);
  return text + "]";
}

std::string ScalarText(const YAML::Node& value, const std::string& where) {
  Require(!value.IsNull(), where, "the value is missing");
  Require(value.IsScalar(), where, "expected a single value, found a list or mapping");
  return value.Scalar();
}

double ParseNumber(const YAML::Node& value, const std::string& where, double min, double max) {
  const std::string text = ScalarText(value, where);
  double number = 0.0;
  Require(YAML::convert<double>::decode(value, number), where,
          "expected a number, got '" + text + "'");
  Require(std::isfinite(number), where, "value must be finite");
  Require(number >= min && number <= max, where,
          "value " + text + " is outside " + RangeText(min, max));
  return number;
}

std::string ParseChoice(const YAML::Node& value, const std::string& where,
                        const std::vector<std::string>& choices) {
  const std::string text = ScalarText(value, where);
  std::string listed;
  for (const std::string& choice : choices) {
    if (choice == text) return text;
    listed += (listed.empty() ? "" : ", ") + choice;
  }
  throw Error(where, "'" + text + "' is not one of: " + listed);
}

// A list of exactly `size` numbers in [min, max], written to values[0 .. size-1]; the field is
// left untouched unless the whole list is valid.
void AddFixedList(ConfigSchema* schema, const std::string& path, double* values, int size,
                  const std::string& doc, double min = kNoMin, double max = kNoMax) {
  const std::string range = RangeText(min, max);
  schema->AddCustom(
      path, "list of " + std::to_string(size) + " floats", range, doc,
      [=](const YAML::Node& value, const std::string& where) {
        Require(value.IsSequence(), where,
                "expected a list of " + std::to_string(size) + " numbers such as " +
                    ListText(values, size));
        Require(static_cast<int>(value.size()) == size, where,
                "expected exactly " + std::to_string(size) + " numbers, got " +
                    std::to_string(value.size()));
        std::vector<double> numbers;
        for (const YAML::Node& item : value) numbers.push_back(ParseNumber(item, where, min, max));
        std::copy(numbers.begin(), numbers.end(), values);
      },
      [=] { return ListText(values, size); });
}

void AddVector3(ConfigSchema* schema, const std::string& path, Eigen::Vector3d* field,
                const std::string& doc, double min = kNoMin, double max = kNoMax) {
  AddFixedList(schema, path, field->data(), 3, doc, min, max);
}

// Seeds are 64-bit unsigned: an int key would cut their range in half.
void AddSeed(ConfigSchema* schema, const std::string& path, std::uint64_t* field,
             const std::string& doc) {
  schema->AddCustom(
      path, "uint64", "[0, 2^64 - 1]", doc,
      [=](const YAML::Node& value, const std::string& where) {
        const std::string text = ScalarText(value, where);
        std::uint64_t seed = 0;
        Require(YAML::convert<std::uint64_t>::decode(value, seed), where,
                "expected an integer in [0, 2^64 - 1], got '" + text + "'");
        *field = seed;
      },
      [=] { return std::to_string(*field); });
}

// ---- Folds ----

// A numeric field of FoldComponent with its YAML name and allowed range (as FoldComponent::Check).
struct FoldNumber {
  const char* name;
  double FoldComponent::*field;
  double min;
  double max;
};

const FoldNumber kFoldNumbers[] = {
    {"amplitude", &FoldComponent::amplitude, -0.1, 0.1},
    {"wavelength", &FoldComponent::wavelength, 0.01, 2.0},
    {"orientation", &FoldComponent::orientation, kNoMin, kNoMax},
    {"phase", &FoldComponent::phase, kNoMin, kNoMax},
    {"drift", &FoldComponent::drift, kNoMin, kNoMax},
};
const char kFoldKeys[] = "amplitude, wavelength, orientation, phase, drift, profile";

void ParseFoldField(const std::string& name, const YAML::Node& value, const std::string& where,
                    FoldComponent* fold) {
  if (name == "profile") {
    StringToEnum(ParseChoice(value, where, EnumNameList<FoldProfile>()), &fold->profile);
    return;
  }
  for (const FoldNumber& number : kFoldNumbers) {
    if (name == number.name) {
      fold->*number.field = ParseNumber(value, where, number.min, number.max);
      return;
    }
  }
  throw Error(where, std::string("unknown fold key (known: ") + kFoldKeys + ")");
}

// One item of `folds`: a mapping of some of the fold keys; absent keys keep their defaults.
FoldComponent ParseFold(const YAML::Node& item, const std::string& where) {
  Require(item.IsMap(), where, "expected a mapping such as {amplitude: 0.008, wavelength: 0.12}");
  FoldComponent fold;
  for (const auto& entry : item) {
    const std::string name = ScalarText(entry.first, where);
    ParseFoldField(name, entry.second, SubKeyWhere(where, "." + name), &fold);
  }
  return fold;
}

std::vector<FoldComponent> ParseFolds(const YAML::Node& value, const std::string& where) {
  Require(value.IsSequence(), where,
          "expected a list of fold mappings such as [{amplitude: 0.008, wavelength: 0.12}]");
  std::vector<FoldComponent> folds;
  for (const YAML::Node& item : value) {
    const std::string index = "[" + std::to_string(folds.size()) + "]";
    folds.push_back(ParseFold(item, SubKeyWhere(where, index)));
  }
  return folds;
}

// YAML flow syntax, e.g. [{amplitude: 0.008, wavelength: 0.12, ..., profile: sine}].
std::string FoldsText(const std::vector<FoldComponent>& folds) {
  std::string text = "[";
  for (size_t i = 0; i < folds.size(); ++i) {
    text += i ? ", {" : "{";
    for (const FoldNumber& number : kFoldNumbers) {
      text += std::string(number.name) + ": " + NumberText(folds[i].*number.field) + ", ";
    }
    text += "profile: " + EnumToString(folds[i].profile) + "}";
  }
  return text + "]";
}

void AddFoldsKey(std::vector<FoldComponent>* folds, ConfigSchema* schema) {
  schema->AddCustom(
      "synth.folds", "list of folds", std::string("{") + kFoldKeys + "}",
      "Fold families, summed: amplitude m, wavelength m, orientation deg (0 = crests run "
      "down), phase deg, drift deg/frame, profile sine or ridge.",
      [folds](const YAML::Node& value, const std::string& where) {
        *folds = ParseFolds(value, where);
      },
      [folds] { return FoldsText(*folds); });
}

// ---- Coarse input ----

void AddCoarseInputKeys(SynthOptions* synth, ConfigSchema* schema) {
  schema->AddEnum("synth.coarse", &synth->coarse,
                  "The coarse meshes: unfolded (the true surface without its folds), smoothed "
                  "(the true surface Taubin-smoothed, synth.smoothing) or exact (the true "
                  "surface at the coarse vertices, the detail between them missing).");
  TaubinSmoothingOptions& smoothing = synth->smoothing;
  schema->AddInt("synth.smoothing.iterations", &smoothing.iterations,
                 "synth.coarse smoothed: Taubin iterations (lambda and mu step each), the "
                 "strength of the smoothing.",
                 1, 100000);
  schema->AddDouble("synth.smoothing.lambda", &smoothing.lambda, "Taubin's shrinking step factor.",
                    1e-3, 1.0);
  schema->AddDouble("synth.smoothing.mu", &smoothing.mu,
                    "Taubin's inflating step factor (negative, usually slightly larger in "
                    "magnitude than lambda; (1 - 2 lambda)(1 - 2 mu) >= -1).",
                    -1.0, 0.0);
}

// ---- Sections ----

void AddSkirtKeys(SkirtOptions* skirt, ConfigSchema* schema) {
  schema->AddDouble("synth.skirt.waist_radius", &skirt->waist_radius,
                    "Radius of the skirt at the waist (top), m.", 0.01, 5.0);
  schema->AddDouble("synth.skirt.hem_radius", &skirt->hem_radius,
                    "Radius of the skirt at the hem (bottom), m; >= waist_radius.", 0.01, 5.0);
  schema->AddDouble("synth.skirt.length", &skirt->length, "Height from waist to hem, m.", 0.01,
                    10.0);
  schema->AddDouble("synth.skirt.flare_exponent", &skirt->flare_exponent,
                    "Radius grows like s^p from waist (s = 0) to hem (s = 1); 1 is a cone.", 1.0,
                    10.0);
  schema->AddDouble("synth.skirt.waist_height", &skirt->waist_height,
                    "Height of the waist above the floor (world y), m.");
  schema->AddInt("synth.skirt.around", &skirt->around, "Coarse mesh vertices around the tube.", 8,
                 100000);
  schema->AddInt("synth.skirt.down", &skirt->down, "Coarse mesh vertices from waist to hem.", 3,
                 100000);
  schema->AddDouble("synth.skirt.sway", &skirt->sway, "Peak sideways sway of the hem, m.", 0.0,
                    1.0);
  schema->AddDouble("synth.skirt.swing", &skirt->swing,
                    "Peak twist of the hem about the vertical axis, degrees.", -90.0, 90.0);
  schema->AddDouble("synth.skirt.flare_wobble", &skirt->flare_wobble,
                    "Peak relative difference of the hem outline's radii from round (fraction).",
                    0.0, 0.5);
  schema->AddDouble("synth.skirt.period", &skirt->period,
                    "Frames per cycle of the low-frequency motion.", 1e-3, 1e9);
}

void AddGeometryKeys(SynthOptions* synth, ConfigSchema* schema) {
  schema->AddString("synth.mesh_path", &synth->mesh_path,
                    "Subject \"mesh\": a mesh file or a folder of per-frame meshes of one "
                    "topology (.ply, .obj, .off, .stl); world y up.");
  schema->AddInt("synth.num_frames", &synth->num_frames,
                 "Frames to generate (at most the meshes in a mesh_path folder).", 1, 1000000);
  schema->AddInt("synth.truth_refinement", &synth->truth_refinement,
                 "True surface edges per coarse edge (a power of two for subject \"mesh\").", 1,
                 16);
  AddFoldsKey(&synth->folds, schema);
  schema->AddDouble("synth.single_wavelength", &synth->single_wavelength,
                    "When > 0, every fold gets this wavelength, m (0.01 to 2); 0 = off.", 0.0, 2.0);
  schema->AddInt("synth.fold_ramp_frames", &synth->fold_ramp_frames,
                 "Folds grow from zero at frame 0 to full at this frame; 0 = full from frame 0 "
                 "(a ramp leaves the reference frame's coarse mesh exact).",
                 0);
  schema->AddDouble("synth.misalignment", &synth->misalignment,
                    "Peak of the smooth random displacement added to the coarse meshes, m.", 0.0,
                    0.1);
  schema->AddDouble("synth.misalignment_wavelength", &synth->misalignment_wavelength,
                    "Spatial wavelength of that displacement field, m.", 0.01, 100.0);
  schema->AddDouble("synth.max_displacement", &synth->max_displacement,
                    "Largest |k| searched along a coarse normal for the true surface, m; "
                    "farther is a miss.",
                    1e-4, 10.0);
}

void AddTextureKeys(TextureOptions* texture, ConfigSchema* schema) {
  schema->AddInt("synth.texture.width", &texture->width, "Texture width, texels (around).", 16,
                 16384);
  schema->AddInt("synth.texture.height", &texture->height, "Texture height, texels (down).", 16,
                 16384);
  schema->AddEnum("synth.texture.pattern", &texture->pattern,
                  "Cloth print: plaid, motifs and noise mixed, or one of them alone.");
  schema->AddDouble("synth.texture.textureless_begin", &texture->textureless_begin,
                    "Start of the plain band, fraction of the height from the top.", 0.0, 1.0);
  schema->AddDouble("synth.texture.textureless_end", &texture->textureless_end,
                    "End of the plain band, fraction of the height (equal to begin: no band).", 0.0,
                    1.0);
  AddVector3(schema, "synth.texture.textureless_color", &texture->textureless_color,
             "Colour of the plain band, RGB in [0, 1].", 0.0, 1.0);
}

void AddRigKeys(RigOptions* rig, ConfigSchema* schema) {
  schema->AddInt("synth.cameras.count", &rig->count,
                 "Cameras, evenly spaced on a ring around the subject.", 1, 1000);
  schema->AddInt("synth.cameras.width", &rig->width, "Image width, pixels.", 16, 20000);
  schema->AddInt("synth.cameras.height", &rig->height, "Image height, pixels.", 16, 20000);
  schema->AddDouble("synth.cameras.focal", &rig->focal, "Focal length, pixels.", 1.0, 1e6);
  schema->AddDouble("synth.cameras.distance", &rig->distance,
                    "Horizontal distance of the cameras from the subject's axis, m.", 0.05, 1e4);
  schema->AddDoubleList("synth.cameras.heights", &rig->heights,
                        "Camera heights above the subject's centre, m; camera c uses entry "
                        "c % size (non-empty).");
  AddFixedList(schema, "synth.cameras.distortion", rig->distortion.data(),
               static_cast<int>(rig->distortion.size()),
               "Lens distortion (k1, k2, p1, p2, k3) of every camera, OpenCV's model.", -10.0,
               10.0);
  schema->AddDouble("synth.cameras.rotation_noise", &rig->rotation_noise,
                    "Calibration error: rotation standard deviation per axis, degrees.", 0.0, 10.0);
  schema->AddDouble("synth.cameras.translation_noise", &rig->translation_noise,
                    "Calibration error: centre offset standard deviation per axis, m.", 0.0, 1.0);
  schema->AddDouble("synth.cameras.focal_noise", &rig->focal_noise,
                    "Calibration error: relative focal length standard deviation.", 0.0, 0.5);
}

void AddRenderKeys(RenderOptions* render, ConfigSchema* schema) {
  schema->AddInt("synth.render.supersampling", &render->supersampling,
                 "Samples per pixel along each axis (anti-aliasing).", 1, 16);
  schema->AddBool("synth.render.cull_back_faces", &render->cull_back_faces,
                  "Skip triangles facing away from the camera (false: the inside of an open "
                  "surface shows).");
  schema->AddDouble("synth.render.near_plane", &render->near_plane,
                    "Camera z of the near clipping plane, m (> 0).", 1e-9);
  schema->AddBool("synth.render.shade", &render->shade,
                  "Lambertian shading: colour * (ambient + diffuse * max(0, n . l)).");
  schema->AddDouble("synth.render.ambient", &render->ambient, "Ambient term of the shading.", 0.0);
  schema->AddDouble("synth.render.diffuse", &render->diffuse, "Diffuse term of the shading.", 0.0);
  AddVector3(schema, "synth.render.light_direction", &render->light_direction,
             "Direction towards the light, world coordinates; non-zero, any length.");
  AddVector3(schema, "synth.render.background", &render->background,
             "Colour of pixels that see no surface, RGB in [0, 1].", 0.0, 1.0);
  schema->AddDouble("synth.render.noise_sigma", &render->noise_sigma,
                    "Standard deviation of Gaussian sensor noise, 8-bit grey levels.", 0.0, 255.0);
  AddSeed(schema, "synth.render.noise_seed", &render->noise_seed,
          "Mixed with synth.seed, the frame and the camera into each image's noise seed.");
}

}  // namespace

void AddSynthKeys(SynthOptions* options, ConfigSchema* schema) {
  schema->AddEnum("synth.subject", &options->subject,
                  "skirt: the built-in flared tube (synth.skirt); mesh: the meshes at "
                  "synth.mesh_path.");
  AddSkirtKeys(&options->skirt, schema);
  AddGeometryKeys(options, schema);
  AddCoarseInputKeys(options, schema);
  AddTextureKeys(&options->texture, schema);
  AddRigKeys(&options->cameras, schema);
  AddRenderKeys(&options->render, schema);
  schema->AddEnum("synth.background", &options->background,
                  "Around the subject: plain (synth.render.background) or per_camera (a "
                  "textured wall of its own in every camera).");
  schema->AddBool("synth.write_masks", &options->write_masks,
                  "Write the subject's silhouettes as foreground masks (masks/<camera>/).");
  AddSeed(schema, "synth.seed", &options->seed,
          "Seed of every random choice (texture, misalignment, calibration and sensor noise).");
}

}  // namespace finecap
