#include "status_convert.h"

#include <optional>
#include <string>

#include "absl/strings/cord.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "geodex/limits.h"
#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "service_limits.h"

namespace geodex::server {
namespace {

constexpr absl::string_view kReasonPayload = "geodex/reason";

// geodex's error messages start with the request field they concern: "sources[2].edge.t: ...".
// Returns that field, or "" when the message does not start with one.
absl::string_view LeadingField(absl::string_view message) {
  const size_t colon = message.find(": ");
  if (colon == absl::string_view::npos || colon == 0) return {};
  absl::string_view field = message.substr(0, colon);
  for (char c : field) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '.' || c == '[' || c == ']' || c == '/';
    if (!ok) return {};
  }
  return field;
}

// The first "--flag_name" a limit's message names, or "".
absl::string_view NamedFlag(absl::string_view message) {
  const size_t start = message.find("--");
  if (start == absl::string_view::npos) return {};
  size_t end = start + 2;
  while (end < message.size() &&
         ((message[end] >= 'a' && message[end] <= 'z') || message[end] == '_')) {
    ++end;
  }
  return end > start + 2 ? message.substr(start + 2, end - start - 2) : absl::string_view();
}

std::string CapMessage(absl::string_view message) {
  if (message.size() <= kMaxStatusMessageBytes) return std::string(message);
  return absl::StrCat(message.substr(0, kMaxStatusMessageBytes - 60), "... (message cut: ",
                      message.size(), " bytes)");
}

}  // namespace

std::string QuoteInput(absl::string_view input) {
  if (input.size() <= kMaxEchoBytes) return absl::StrCat("\"", input, "\"");
  size_t cut = kMaxEchoBytes;
  while (cut > 0 && (static_cast<unsigned char>(input[cut]) & 0xC0) == 0x80) --cut;  // whole UTF-8
  return absl::StrCat("\"", input.substr(0, cut), "...\" (cut: ", input.size(), " bytes)");
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

  // Rich error details (google.rpc.Status in the grpc-status-details-bin trailer): BadRequest
  // naming the field for INVALID_ARGUMENT, ErrorInfo naming the flag for a limit.
  google::rpc::Status details;
  if (status.code() == absl::StatusCode::kInvalidArgument) {
    absl::string_view field = LeadingField(message);
    if (!field.empty()) {
      google::rpc::BadRequest bad_request;
      google::rpc::BadRequest::FieldViolation* violation = bad_request.add_field_violations();
      violation->set_field(std::string(field));
      violation->set_description(message.substr(field.size() + 2));
      details.add_details()->PackFrom(bad_request);
    }
  } else if (status.code() == absl::StatusCode::kResourceExhausted) {
    google::rpc::ErrorInfo info;
    info.set_domain("geodex.v1");
    absl::string_view flag = NamedFlag(message);
    const bool queue_full = message.rfind("compute queue full", 0) == 0;
    info.set_reason(queue_full ? "QUEUE_FULL" : flag.empty() ? "RESOURCE_EXHAUSTED" : "LIMIT");
    if (!flag.empty()) (*info.mutable_metadata())["flag"] = std::string(flag);
    details.add_details()->PackFrom(info);
  } else if (auto reason = status.GetPayload(kReasonPayload)) {
    google::rpc::ErrorInfo info;
    info.set_domain("geodex.v1");
    info.set_reason(std::string(*reason));
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
