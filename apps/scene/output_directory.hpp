#pragma once
// Where a run writes: never half over an earlier run. The run writes into `<dir>.partial`
// and moves it to `<dir>` only when it ends (finished, failed or interrupted by an error, each
// with its summary). `<dir>` that exists is refused before any work unless `replace` is set;
// then the old directory is removed only after the new one is complete.
#include <filesystem>
#include <string>
#include <system_error>

#include "scene/json_reader.hpp"

namespace stokescontact::apps {

class OutputDirectory {
 public:
  // Checks only; creates nothing. `create_parent`: a missing parent directory is made at
  // open() (the default out/<name>); otherwise it must exist.
  OutputDirectory(std::filesystem::path final_dir, bool replace, bool create_parent = false)
      : final_(std::move(final_dir)), partial_(final_.string() + ".partial"), replace_(replace) {
    if (final_.empty()) throw SceneError("--output", "must name a directory");
    if (std::filesystem::exists(final_) && !replace_)
      throw SceneError("--output", "'" + final_.string() +
                                       "' exists; a run writes a fresh directory (give --replace to replace it "
                                       "once the new run has finished)");
    if (std::filesystem::exists(final_) && !std::filesystem::is_directory(final_))
      throw SceneError("--output", "'" + final_.string() + "' exists and is not a directory");
    const std::filesystem::path parent = std::filesystem::absolute(final_).parent_path();
    if (!create_parent && !std::filesystem::is_directory(parent))
      throw SceneError("--output", "the parent directory '" + parent.string() + "' does not exist");
  }

  // Creates `<dir>.partial` (a leftover of an earlier interrupted run is removed first).
  const std::filesystem::path& open() {
    std::filesystem::create_directories(std::filesystem::absolute(final_).parent_path());
    std::filesystem::remove_all(partial_);
    std::filesystem::create_directory(partial_);
    return partial_;
  }

  // Moves the finished `<dir>.partial` to `<dir>`; returns `<dir>`.
  const std::filesystem::path& commit() {
    std::filesystem::path old;
    if (std::filesystem::exists(final_)) {
      old = final_.string() + ".old";
      std::filesystem::remove_all(old);
      std::filesystem::rename(final_, old);
    }
    std::filesystem::rename(partial_, final_);
    if (!old.empty()) std::filesystem::remove_all(old);
    return final_;
  }

  const std::filesystem::path& final_path() const { return final_; }

 private:
  std::filesystem::path final_, partial_;
  bool replace_ = false;
};

}  // namespace stokescontact::apps
