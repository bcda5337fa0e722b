#pragma once  // SPDX-License-Identifier: Apache-2.0
// Session control at run time (docs/PROTOCOL.md): a scene or a material is built on a thread of
// its own while the physics goes on, one at a time; the physics thread takes it once ready and
// swaps it in between ticks; an organ no longer used is destroyed on a thread of its own (a
// compliance worker may still be factorising). Every request's outcome, accepted or refused with
// its reason, is kept (the last 8) for the scene state. The builders are passed in, so this is
// tested without organs or DDS. Physics thread only.
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/scene_file.hpp"

namespace viscera::runtime {

struct Organ;

/// A build that finished: the organ, or why it could not be built.
struct Prepared {
  protocol::SessionRequest request;
  std::string what;  ///< "scene liver-12k", "material youngs_modulus_pa 8000"
  std::shared_ptr<Organ> organ;  ///< null when the build failed
  std::string error;
};

class SessionControl {
 public:
  using SceneBuilder = std::function<std::shared_ptr<Organ>(const SceneSpec&)>;
  using MaterialBuilder =
      std::function<std::shared_ptr<Organ>(const std::shared_ptr<const Organ>& current, const protocol::MaterialChange&, double rate_hz)>;
  static constexpr std::size_t kOutcomesKept = 8;

  SessionControl(std::string scene_dir, SceneBuilder build_scene, MaterialBuilder build_material);
  /// Never waits for a build or a destruction still running: it finishes on its own thread.
  ~SessionControl();
  SessionControl(const SessionControl&) = delete;
  SessionControl& operator=(const SessionControl&) = delete;

  /// Starts building the scene `request.scene_name` of the scene folder (on `domain_id`, the
  /// server's), or returns why not: busy, no such scene (listing those there are), or the scene
  /// file's error.
  std::optional<std::string> start_scene(const protocol::SessionRequest& request, std::uint32_t domain_id);
  /// Starts building `current` with the request's material change for a physics rate of
  /// `rate_hz`, or returns why not (busy).
  std::optional<std::string> start_material(const protocol::SessionRequest& request, std::shared_ptr<const Organ> current, double rate_hz);
  /// The finished build, if any (never blocks).
  std::optional<Prepared> take_ready();
  /// Blocks until the build in progress, if any, has finished (lockstep).
  void wait_ready() const;
  /// What is being built ("" when nothing).
  std::string preparing() const { return preparing_ ? preparing_->what : std::string(); }
  /// Whether a material change is being built (from the running organ's mesh, which must not change meanwhile).
  bool preparing_material() const { return preparing_ && preparing_->request.action == protocol::Action::set_material; }

  /// Keeps a request's outcome (the last kOutcomesKept, oldest first).
  void record(const protocol::SessionRequest& request, bool accepted, const std::string& message);
  const std::deque<protocol::RequestOutcome>& outcomes() const { return outcomes_; }

  const SceneListing& scenes() const { return scenes_; }
  void refresh_scenes();
  const std::string& scene_dir() const { return scene_dir_; }

  /// An organ no longer used, destroyed on a thread of its own.
  void retire(std::shared_ptr<Organ> organ);
  /// Builds and destructions left to finish on their own threads by destroyed SessionControls.
  static int abandoned();

 private:
  struct Preparing {
    std::future<std::shared_ptr<Organ>> organ;
    protocol::SessionRequest request;
    std::string what;
  };
  std::string scene_dir_;
  SceneBuilder build_scene_;
  MaterialBuilder build_material_;
  std::optional<Preparing> preparing_;
  std::deque<protocol::RequestOutcome> outcomes_;
  SceneListing scenes_;
  std::vector<std::future<void>> retiring_;
};

/// A material change as one line: "youngs_modulus_pa 8000, shear_q 3".
std::string describe_change(const protocol::MaterialChange& m);

}  // namespace viscera::runtime
