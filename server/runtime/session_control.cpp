#include "viscera/runtime/session_control.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

namespace viscera::runtime {

namespace {
std::atomic<int> g_abandoned{0};

template <class T>
bool ready(const std::future<T>& f) {
  return f.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

/// Lets a build or a destruction finish on a thread of its own instead of waiting for it.
template <class T>
void abandon(std::future<T> f) {
  ++g_abandoned;
  std::thread([f = std::move(f)]() mutable { f.wait(); }).detach();
}
}  // namespace

SessionControl::SessionControl(std::string scene_dir, SceneBuilder build_scene, MaterialBuilder build_material)
    : scene_dir_(std::move(scene_dir)), build_scene_(std::move(build_scene)), build_material_(std::move(build_material)) {
  refresh_scenes();
}

SessionControl::~SessionControl() {
  if (preparing_ && !ready(preparing_->organ)) abandon(std::move(preparing_->organ));
  for (auto& f : retiring_)
    if (!ready(f)) abandon(std::move(f));
}

int SessionControl::abandoned() { return g_abandoned.load(); }

void SessionControl::refresh_scenes() { scenes_ = list_scenes(scene_dir_); }

std::optional<std::string> SessionControl::start_scene(const protocol::SessionRequest& request, std::uint32_t domain_id) {
  if (preparing_) return "busy: still preparing " + preparing_->what;
  const std::string path = (std::filesystem::path(scene_dir_) / (request.scene_name + ".json")).string();
  if (!std::filesystem::exists(path)) {
    std::string list;
    for (const auto& n : scenes_.loadable) list += (list.empty() ? "" : ", ") + n;
    return "no scene '" + request.scene_name + "' in " + scene_dir_ + " (available: " + list + ")";
  }
  SceneSpec spec;
  try {
    spec = read_scene_file(path);
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  spec.domain_id = domain_id;  // the server stays on its domain
  if (request.scene_seed) reseed_regions(spec, *request.scene_seed);
  preparing_ =
      Preparing{std::async(std::launch::async, [spec, build = build_scene_] { return build(spec); }), request, "scene " + request.scene_name};
  return std::nullopt;
}

std::optional<std::string> SessionControl::start_material(const protocol::SessionRequest& request, std::shared_ptr<const Organ> current,
                                                          double rate_hz) {
  if (preparing_) return "busy: still preparing " + preparing_->what;
  // The current organ stays alive for the build (shared), even if the server stops meanwhile.
  preparing_ = Preparing{std::async(std::launch::async, [current = std::move(current), change = request.material, rate_hz,
                                                         build = build_material_] { return build(current, change, rate_hz); }),
                         request, "material " + describe_change(request.material)};
  return std::nullopt;
}

void SessionControl::wait_ready() const {
  if (preparing_) preparing_->organ.wait();
}

std::optional<Prepared> SessionControl::take_ready() {
  if (!preparing_ || !ready(preparing_->organ)) return std::nullopt;
  Prepared p{preparing_->request, preparing_->what, nullptr, {}};
  try {
    p.organ = preparing_->organ.get();
  } catch (const std::exception& e) {
    p.error = e.what();
  }
  preparing_.reset();
  return p;
}

void SessionControl::record(const protocol::SessionRequest& request, bool accepted, const std::string& message) {
  outcomes_.push_back({request.client_id, request.request_seq, request.action, accepted, message.substr(0, 1000)});
  while (outcomes_.size() > kOutcomesKept) outcomes_.pop_front();
}

void SessionControl::retire(std::shared_ptr<Organ> organ) {
  if (organ) retiring_.push_back(std::async(std::launch::async, [o = std::move(organ)]() mutable { o.reset(); }));
  std::erase_if(retiring_, [](const std::future<void>& f) { return ready(f); });
}

std::string describe_change(const protocol::MaterialChange& m) {
  std::string out;
  const auto add = [&](const char* name, const std::optional<double>& v) {
    if (!v) return;
    char b[80];
    std::snprintf(b, sizeof b, "%s%s %.6g", out.empty() ? "" : ", ", name, *v);
    out += b;
  };
  add("youngs_modulus_pa", m.youngs_modulus_pa);
  add("poisson_ratio", m.poisson_ratio);
  add("density_kg_m3", m.density_kg_m3);
  add("shear_q", m.shear_q);
  add("damping_per_s", m.damping_per_s);
  if (m.file_text) out = "file " + m.file_name + (out.empty() ? "" : " with " + out);
  return out;
}

}  // namespace viscera::runtime
