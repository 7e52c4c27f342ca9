#include "field_promoter.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <utility>

#include "geodex/distance_field.h"

namespace geodex::server {

FieldPromoter::FieldPromoter(FieldCache* cache, ServiceCounters* counters, uint64_t max_windows,
                             size_t capacity)
    : cache_(cache), counters_(counters), max_windows_(max_windows), capacity_(capacity) {
  thread_ = std::thread([this] { Run(); });
}

FieldPromoter::~FieldPromoter() { Stop(); }

void FieldPromoter::Offer(std::shared_ptr<const StoredMesh> mesh, std::vector<SurfacePoint> sources,
                          GeodesicOptions options, std::string key) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (stopped_ || pending_.contains(key)) return;
    if (queue_.size() >= capacity_) {
      counters_->background_dropped.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    // The caller's cancellation must not reach this solve: it has its own token and budget.
    options.cancel = &cancel_;
    options.max_windows = max_windows_;
    pending_.insert(key);
    queue_.push_back({std::move(mesh), std::move(sources), std::move(options), std::move(key)});
  }
  wake_.notify_one();
}

void FieldPromoter::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (stopped_) return;
    stopped_ = true;
    queue_.clear();
  }
  cancel_.Cancel();
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void FieldPromoter::Run() {
  // The lowest priority this thread may take (Linux: a thread's own nice value), so that a
  // foreground call never waits for it on a busy machine.
  setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
  while (true) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mu_);
      wake_.wait(lock, [&] { return stopped_ || !queue_.empty(); });
      if (stopped_) return;
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    if (!cache_->Contains(job.key)) {
      absl::StatusOr<DistanceField> field =
          ComputeDistanceField(*job.mesh->mesh, job.sources, job.options);
      if (field.ok()) {
        counters_->background_solves.fetch_add(1, std::memory_order_relaxed);
        counters_->windows_processed.fetch_add(field->stats.windows_processed,
                                               std::memory_order_relaxed);
        cache_->Insert(job.key, std::make_shared<const DistanceField>(*std::move(field)));
      }  // else cancelled or over its budget: the paths keep running A*
    }
    std::lock_guard<std::mutex> lock(mu_);
    pending_.erase(job.key);
  }
}

}  // namespace geodex::server
