#include "status_convert.h"

#include <optional>
#include <string>

#include "absl/strings/cord.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "geodex/limits.h"
#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "service_limits.h"

namespace geodex::server {
namespace {

// The payloads of the typed errors (type URLs private to this file).
constexpr absl::string_view kReasonPayload = "geodex/reason";
constexpr absl::string_view kFieldPayload = "geodex/field";
constexpr absl::string_view kFlagPayload = "geodex/flag";

std::string PayloadOf(const absl::Status& status, absl::string_view url) {
  auto payload = status.GetPayload(url);  // absl::optional<absl::Cord>
  return payload ? std::string(*payload) : std::string();
}

std::string CapMessage(absl::string_view message) {
  if (message.size() <= kMaxStatusMessageBytes) return std::string(message);
  return absl::StrCat(message.substr(0, kMaxStatusMessageBytes - 60),
                      "... (message cut: ", message.size(), " bytes)");
}

}  // namespace

std::string QuoteInput(absl::string_view input) {
  if (input.size() <= kMaxEchoBytes) return absl::StrCat("\"", input, "\"");
  size_t cut = kMaxEchoBytes;
  while (cut > 0 && (static_cast<unsigned char>(input[cut]) & 0xC0) == 0x80) --cut;  // whole UTF-8
  return absl::StrCat("\"", input.substr(0, cut), "...\" (cut: ", input.size(), " bytes)");
}

absl::Status FieldError(absl::string_view field, absl::string_view description) {
  absl::Status status = absl::InvalidArgumentError(absl::StrCat(field, ": ", description));
  status.SetPayload(kFieldPayload, absl::Cord(field));
  return status;
}

absl::Status ServerLimitError(absl::string_view flag, absl::string_view message) {
  absl::Status status = absl::ResourceExhaustedError(message);
  status.SetPayload(kReasonPayload, absl::Cord("LIMIT"));
  status.SetPayload(kFlagPayload, absl::Cord(flag));
  return status;
}

absl::Status QueueFullError(absl::string_view message) {
  absl::Status status = absl::ResourceExhaustedError(message);
  status.SetPayload(kReasonPayload, absl::Cord("QUEUE_FULL"));
  return status;
}

absl::Status MeshNotFoundError(absl::string_view field, absl::string_view message) {
  absl::Status status = absl::NotFoundError(absl::StrCat(field, ": ", message));
  status.SetPayload(kReasonPayload, absl::Cord("MESH_NOT_FOUND"));
  status.SetPayload(kFieldPayload, absl::Cord(field));
  return status;
}

absl::Status UnreachableError(absl::string_view message) {
  absl::Status status = absl::FailedPreconditionError(message);
  status.SetPayload(kReasonPayload, absl::Cord("UNREACHABLE"));
  return status;
}

grpc::Status ToGrpcStatus(const absl::Status& status) {
  if (status.ok()) return grpc::Status::OK;
  // absl::StatusCode and grpc::StatusCode share the canonical numbering (google.rpc.Code).
  int code = static_cast<int>(status.code());
  if (code < 0 || code > 16) code = grpc::StatusCode::UNKNOWN;
  std::string message(status.message());
  if (std::optional<Limit> limit = ExceededLimit(status)) {
    absl::StrAppend(&message, " (server flag --", FlagOfLimit(*limit), ")");
  }
  message = CapMessage(message);

  // Rich error details (google.rpc.Status in the grpc-status-details-bin trailer), from the
  // payloads only: a BadRequest naming the field, an ErrorInfo with the reason (and the flag).
  google::rpc::Status details;
  const std::string field = PayloadOf(status, kFieldPayload);
  if (!field.empty()) {
    google::rpc::BadRequest bad_request;
    google::rpc::BadRequest::FieldViolation* violation = bad_request.add_field_violations();
    violation->set_field(field);
    violation->set_description(
        absl::StartsWith(message, field + ": ") ? message.substr(field.size() + 2) : message);
    details.add_details()->PackFrom(bad_request);
  }
  std::string reason = PayloadOf(status, kReasonPayload);
  std::string flag = PayloadOf(status, kFlagPayload);
  if (std::optional<Limit> limit = ExceededLimit(status)) {  // a core limit: the flag that set it
    reason = "LIMIT";
    flag = FlagOfLimit(*limit);
  }
  if (reason.empty() && status.code() == absl::StatusCode::kResourceExhausted) {
    reason = "RESOURCE_EXHAUSTED";  // the mesh budget, a full data directory
  }
  if (!reason.empty()) {
    google::rpc::ErrorInfo info;
    info.set_domain("geodex.v1");
    info.set_reason(reason);
    if (!flag.empty()) (*info.mutable_metadata())["flag"] = flag;
    details.add_details()->PackFrom(info);
  }
  if (details.details_size() == 0) {
    return grpc::Status(static_cast<grpc::StatusCode>(code), message);
  }
  details.set_code(code);
  details.set_message(message);
  return grpc::Status(static_cast<grpc::StatusCode>(code), message, details.SerializeAsString());
}

}  // namespace geodex::server
