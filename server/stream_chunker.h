#pragma once

// Cuts a long result into stream messages of about `budget_bytes` each, far below gRPC's default
// 4 MiB receive limit. Lists of points (polylines) or faces too long for one message are split into
// pieces that repeat the item's header and set `continued` on all but the last (geodex.proto,
// "Streaming of long results").

#include <cstddef>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "geodex/shortest_path.h"
#include "geodex/v1/geodex.pb.h"
#include "proto_convert.h"

namespace geodex::server {

// Produces the next message of a stream into *out; false when the stream has ended.
template <typename Response>
using MessageProducer = std::function<bool(Response* out)>;

// What a stream's `next` gave: a message, nothing yet (its work still runs), or the end.
enum class Produced { kMessage, kLater, kEnd };

// A streamed query's result. Either every message is ready when the query returns (a
// MessageProducer), or messages appear while `work` runs (a matrix's rows as they finish): the
// reactor starts writing at once, runs work(ready) on the compute thread, and polls `next` again
// whenever `ready()` is called (from any thread) and after each write. The stream ends at kEnd
// once `work` has returned; an error from `work` ends it with that status.
template <typename Response>
struct MessageStream {
  using Next = std::function<Produced(Response* out)>;
  using Work = std::function<absl::Status(const std::function<void()>& ready)>;

  MessageStream() = default;
  MessageStream(MessageProducer<Response> producer)  // NOLINT: every message ready
      : next([p = std::move(producer)](Response* out) {
          return p(out) ? Produced::kMessage : Produced::kEnd;
        }) {}
  MessageStream(Next next_message, Work run) : next(std::move(next_message)), work(std::move(run)) {}

  Next next;
  Work work;  // empty: nothing to wait for
};

template <typename Response>
class StreamChunker {
 public:
  explicit StreamChunker(size_t budget_bytes) : budget_(budget_bytes) { messages_.emplace_back(); }

  Response& current() { return messages_.back(); }
  Response& first() { return messages_.front(); }
  Response& last() { return messages_.back(); }

  // Counts bytes added to the current message.
  void Account(size_t bytes) { bytes_ += bytes; }
  bool Full() const { return bytes_ >= budget_; }
  // Starts the next message when the current one is full.
  void MakeRoom() {
    if (Full()) {
      messages_.emplace_back();
      bytes_ = 0;
    }
  }

  // Appends one item holding a point list. `new_item(message)` adds a new item with its header
  // fields set to the message and returns it; `points_of(item)` is its repeated PathPoint field.
  template <typename NewItem>
  void AppendPolyline(const std::vector<PathPoint>& points, NewItem new_item) {
    MakeRoom();
    auto* item = new_item(current());
    const size_t header = item->ByteSizeLong() + 4;
    Account(header);
    for (const PathPoint& p : points) {
      if (Full()) {
        item->set_continued(true);
        MakeRoom();
        item = new_item(current());
        Account(header);
      }
      v1::PathPoint* out = item->add_points();
      PathPointToProto(p, out);
      Account(out->ByteSizeLong() + 3);
    }
  }

  // The messages, as a producer for a streaming reactor (at least one message).
  MessageProducer<Response> TakeProducer() {
    auto messages = std::make_shared<std::vector<Response>>(std::move(messages_));
    auto next = std::make_shared<size_t>(0);
    return [messages, next](Response* out) {
      if (*next >= messages->size()) return false;
      out->Swap(&(*messages)[(*next)++]);
      return true;
    };
  }

 private:
  const size_t budget_;
  size_t bytes_ = 0;
  std::vector<Response> messages_;
};

}  // namespace geodex::server
