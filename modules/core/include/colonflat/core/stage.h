#pragma once
// A pipeline stage (VMTK-style): one class declaring its inputs, outputs and parameters. From the
// declaration come the stand-alone command `colonflat <stage> IN -o OUT [--param ...]`, its
// --help, range checks, --params-in/--params-out JSON, and the in-memory chaining in
// `colonflat run`. Alone or chained, a stage runs the same run() on the same data.
#include <any>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/error.h"
#include "colonflat/core/params.h"
#include "colonflat/core/tool.h"

namespace cf {

// A kind of data passed between stages, with its file reader and writer.
struct ArtifactType {
  std::string name;         // "mesh", "volume", "mask", "loops", "flat", "image"
  std::string description;  // for --help: "triangle mesh (.vtp .vtk .off .obj .ply .stl)"
  // Reads a file into a value; throws InputError.
  std::function<std::any(const std::filesystem::path&)> read;
  // Writes a value, or its stand-in (compact below), to `tmp` (a temporary path with the target's
  // extension); the stand-in gives the same file. `target` names the final file for messages.
  // The caller renames tmp -> target when every output is written.
  std::function<void(const std::any&, const std::filesystem::path& tmp, const std::filesystem::path& target)> write;
  // Output extensions the writer knows (lower case with the dot, e.g. ".vtp", ".nii.gz"); empty =
  // not declared (then the writer itself refuses an unknown one, after the work).
  std::vector<std::string> extensions = {};
  // Optional, for `colonflat run`: a smaller stand-in of a value that no later stage reads, or
  // whose later readers all take the stand-in (Port::reads_stand_in) (kept while the other stages
  // run, so their peak memory is lower), or nothing when the value cannot be held smaller without
  // loss; and the value back from its stand-in, equal to the original (voxel for voxel, same
  // geometry and header; vertex and face for face). Both empty: never compacted.
  std::function<std::optional<std::any>(const std::any&)> compact = {};
  std::function<std::any(const std::any&)> expand = {};
};

struct Port {
  std::string name;           // key in the artifact bag, and CLI option name for secondary ports
  const ArtifactType* type;   // never null
  std::string help;
  std::string file_name;      // default file name in run and debug folders, e.g. "surface.vtp"
  bool required = true;       // inputs: must be given; outputs: always produced
  // Inputs: the stage also takes the value as its type's stand-in (ArtifactType::compact), so
  // `colonflat run` may hold it so until this stage and after (e.g. render's snapshot meshes as
  // triangle lists while flatten runs).
  bool reads_stand_in = false;
};

struct StageSpec {
  std::string name;     // "denoise"
  std::string summary;  // one line
  std::vector<Port> inputs, outputs;
};

// Named values flowing between stages.
class ArtifactBag {
 public:
  bool has(const std::string& name) const { return items_.count(name) != 0; }
  void put(const std::string& name, std::any value) { items_[name] = std::move(value); }
  const std::any& raw(const std::string& name) const;
  template <class T>
  const T& get(const std::string& name) const {
    const T* p = std::any_cast<T>(&raw(name));
    if (!p) throw Error("artifact '" + name + "' has an unexpected type");
    return *p;
  }
  template <class T>
  T take(const std::string& name) {
    T v = std::move(const_cast<T&>(get<T>(name)));
    items_.erase(name);
    return v;
  }
  void erase(const std::string& name) { items_.erase(name); }

 private:
  std::map<std::string, std::any> items_;
};

// The value of artifact `name` as a T. When the run holds it as its type's stand-in
// (ArtifactType::compact, `colonflat run` from the stage after its last reader on), the value is
// expanded and put back in its place first (the stand-in is freed then).
template <class T>
const T& expanded(ArtifactBag& bag, const std::string& name, const ArtifactType& type) {
  if (!std::any_cast<T>(&bag.raw(name)) && type.expand) bag.put(name, type.expand(bag.raw(name)));
  return bag.get<T>(name);
}

// What a running stage may use: a progress stream and its report (counts, timings).
struct RunContext {
  std::ostream* log = nullptr;  // progress lines; null = quiet
  nlohmann::json report = nlohmann::json::object();
  // Writes one progress line (thread-safe: the runner's "still running" heartbeat shares `log`).
  void progress(const std::string& line) const;
  // A stage calls release_input(port), on its own thread, once it reads no more of input `port`'s
  // value (what it still needs of it copied before) and will not touch the bag's entry again in
  // this run. `colonflat run` may then hold the artifact as its type's stand-in for the rest of the
  // stage (ParkedArtifacts::park_released), e.g. the CT in 16 bits from segment's crop on. Outside
  // a run (input_released unset) nothing happens.
  std::function<void(const std::string& port)> input_released;
  void release_input(const std::string& port) const {
    if (input_released) input_released(port);
  }
};

class Stage {
 public:
  virtual ~Stage() = default;
  virtual const StageSpec& spec() const = 0;
  virtual std::vector<ParamInfo> params() const = 0;
  virtual void add_cli_options(CLI::App& app) = 0;
  virtual nlohmann::json params_json() const = 0;
  virtual void set_params_json(const nlohmann::json& j, const std::string& where) = 0;
  virtual void validate_params() const = 0;
  // Reads spec().inputs from `bag`, puts spec().outputs into it. Throws cf::Error.
  virtual void run(ArtifactBag& bag, RunContext& ctx) = 0;
};

// Implements the parameter plumbing of Stage from a ParamTable over an Options struct.
template <class O>
class StageWithOptions : public Stage {
 public:
  O& options() { return opts_; }
  const O& options() const { return opts_; }
  std::vector<ParamInfo> params() const override { return table().info(); }
  void add_cli_options(CLI::App& app) override { table().add_to(app, opts_); }
  nlohmann::json params_json() const override { return table().to_json(opts_); }
  void set_params_json(const nlohmann::json& j, const std::string& where) override {
    table().from_json(j, opts_, where);
  }
  void validate_params() const override { table().validate(opts_); }

 protected:
  virtual const ParamTable<O>& table() const = 0;
  O opts_{};
};

using StageFactory = std::function<std::unique_ptr<Stage>()>;

// The stand-alone command of a stage: `colonflat <stage> INPUT -o OUTPUT [--<port> FILE]...
// [--report FILE.json] [--params-in F] [--params-out F] [--quiet] [params]`. It runs the stage
// through the same runner as `colonflat run` (core/stage_runner.h).
std::unique_ptr<Tool> make_stage_tool(StageFactory factory);

// Reads a JSON file (InputError on failure).
nlohmann::json read_json_file(const std::filesystem::path& path);

}  // namespace cf
