#pragma once

// What a streamed query returns to its reactor (MessageStream), and ProducerOf for results whose
// messages are all ready. The cutting of long results into messages is proto/convert's
// (geometry_convert.h), far below gRPC's default 4 MiB receive limit.

#include <cstddef>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "absl/status/status.h"

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
  MessageStream(Next next_message, Work run)
      : next(std::move(next_message)), work(std::move(run)) {}

  Next next;
  Work work;  // empty: nothing to wait for
};

// A stream whose messages are all ready (the section-6 geometry, cut by proto/convert's
// geometry_convert.h), as a producer for a streaming reactor.
template <typename Response>
MessageProducer<Response> ProducerOf(std::vector<Response> messages) {
  auto all = std::make_shared<std::vector<Response>>(std::move(messages));
  auto next = std::make_shared<size_t>(0);
  return [all, next](Response* out) {
    if (*next >= all->size()) return false;
    out->Swap(&(*all)[(*next)++]);
    return true;
  };
}

}  // namespace geodex::server
