#pragma once

// What each running geodex.v1 call is about (its mesh and number of sources), for its log line.
// The service records it once the request is parsed (requests are parsed in the handlers, after
// the token check); the metrics interceptor reads it when the call ends and forgets it when the
// call is destroyed. Keyed by the call's ServerContext.

#include <mutex>
#include <string>

#include "absl/container/flat_hash_map.h"
#include "google/protobuf/message.h"

namespace geodex::server {

class CallDescriptions {
 public:
  struct Entry {
    std::string mesh;  // request's `mesh` or `name` field, or the created mesh's name
    int sources = 0;
  };

  // From a request message's `mesh`/`name` and `sources`/`from` fields.
  void Describe(const void* call, const google::protobuf::Message& request) {
    Entry entry;
    entry.mesh = StringField(request, "mesh");
    if (entry.mesh.empty()) entry.mesh = StringField(request, "name");
    const auto* sources = request.GetDescriptor()->FindFieldByName("sources");
    if (sources != nullptr && sources->is_repeated()) {
      entry.sources = request.GetReflection()->FieldSize(request, sources);
    } else if (request.GetDescriptor()->FindFieldByName("from") != nullptr) {
      entry.sources = 1;
    }
    std::lock_guard<std::mutex> lock(mu_);
    entries_[call] = std::move(entry);
  }
  void SetMesh(const void* call, const std::string& mesh) {
    std::lock_guard<std::mutex> lock(mu_);
    entries_[call].mesh = mesh;
  }
  Entry Find(const void* call) const {
    std::lock_guard<std::mutex> lock(mu_);
    auto it = entries_.find(call);
    return it == entries_.end() ? Entry() : it->second;
  }
  void Forget(const void* call) {
    std::lock_guard<std::mutex> lock(mu_);
    entries_.erase(call);
  }

 private:
  static std::string StringField(const google::protobuf::Message& m, const char* name) {
    const google::protobuf::FieldDescriptor* field = m.GetDescriptor()->FindFieldByName(name);
    if (field == nullptr || field->is_repeated() ||
        field->type() != google::protobuf::FieldDescriptor::TYPE_STRING) {
      return "";
    }
    return m.GetReflection()->GetString(m, field);
  }

  mutable std::mutex mu_;
  absl::flat_hash_map<const void*, Entry> entries_;
};

}  // namespace geodex::server
