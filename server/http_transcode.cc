#include "http_transcode.h"

#include <cctype>
#include <functional>
#include <map>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "absl/time/time.h"
#include "geodex/gis_formats.h"
#include "google/protobuf/util/json_util.h"
#include "google/rpc/status.pb.h"
#include "status_convert.h"

namespace geodex::server {
namespace {

namespace pb = google::protobuf;

constexpr char kService[] = "geodex.v1.Geodex";
constexpr char kCollection[] = "/v1/meshes";

const pb::ServiceDescriptor& Service() {
  static const pb::ServiceDescriptor* service =
      pb::DescriptorPool::generated_pool()->FindServiceByName(kService);
  return *service;  // linked in with geodex_proto: never null
}

// "FindShortestPath" -> "findShortestPath": the custom verb of a method.
std::string LowerCamel(const std::string& name) {
  std::string out = name;
  if (!out.empty()) out[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(out[0])));
  return out;
}

std::unique_ptr<pb::Message> NewMessage(const pb::Descriptor* type) {
  return std::unique_ptr<pb::Message>(
      pb::MessageFactory::generated_factory()->GetPrototype(type)->New());
}

// The media type without parameters, lowercase ("application/json; charset=utf-8" -> ...).
std::string BareMediaType(const std::string& content_type) {
  std::string type(absl::StripAsciiWhitespace(content_type.substr(0, content_type.find(';'))));
  absl::AsciiStrToLower(&type);
  return type;
}

std::string PercentDecode(absl::string_view in) {
  std::string out;
  for (size_t i = 0; i < in.size(); ++i) {
    if (in[i] == '+') {
      out += ' ';
    } else if (in[i] == '%' && i + 2 < in.size() &&
               std::isxdigit(static_cast<unsigned char>(in[i + 1])) &&
               std::isxdigit(static_cast<unsigned char>(in[i + 2]))) {
      int value = 0;
      (void)absl::SimpleHexAtoi(in.substr(i + 1, 2), &value);
      out += static_cast<char>(value);
      i += 2;
    } else {
      out += in[i];
    }
  }
  return out;
}

// A field of `type` by its proto name or its JSON name.
const pb::FieldDescriptor* FindField(const pb::Descriptor* type, const std::string& name) {
  if (const pb::FieldDescriptor* field = type->FindFieldByName(name)) return field;
  for (int i = 0; i < type->field_count(); ++i) {
    if (type->field(i)->json_name() == name) return type->field(i);
  }
  return nullptr;
}

using terrain::JsonQuoted;  // a JSON string literal (RFC 8259 escapes), as the GIS files write

// Query parameters (but `timeout`) set the request's scalar fields: "page_size=10",
// "dem.step=2". They are written as a JSON object and read by the JSON parser, so a value is
// checked exactly as the same value in a body would be. (No google.protobuf.Struct here: its map's
// inline code crashed under ThreadSanitizer with Debian's uninstrumented libprotobuf.)
absl::Status SetFieldsFromQuery(const std::map<std::string, std::string>& params,
                                pb::Message* request) {
  struct Node {
    std::string json;                    // a leaf's value
    std::map<std::string, Node> fields;  // an object's members
  };
  Node root;
  for (const auto& [key, value] : params) {
    const pb::Descriptor* type = request->GetDescriptor();
    Node* at = &root;
    const std::vector<std::string> parts = absl::StrSplit(key, '.');
    for (size_t i = 0; i < parts.size(); ++i) {
      const pb::FieldDescriptor* field = FindField(type, parts[i]);
      if (field == nullptr) {
        return absl::InvalidArgumentError(
            absl::StrCat("query parameter ", key, ": ", type->full_name(), " has no field ",
                         parts[i], " (a request's fields go in the JSON body)"));
      }
      if (field->is_repeated() || (i + 1 < parts.size()) != (field->message_type() != nullptr)) {
        return absl::InvalidArgumentError(absl::StrCat(
            "query parameter ", key, ": not a single value; send it in the JSON body"));
      }
      at = &at->fields[field->name()];
      if (i + 1 < parts.size()) {
        type = field->message_type();
        continue;
      }
      // Numbers as strings: the JSON mapping accepts both; booleans as the literals.
      const bool literal = field->cpp_type() == pb::FieldDescriptor::CPPTYPE_BOOL &&
                           (value == "true" || value == "false");
      at->json = literal ? value : JsonQuoted(value);
    }
  }
  std::function<std::string(const Node&)> write = [&](const Node& node) {
    if (node.fields.empty()) return node.json.empty() ? std::string("{}") : node.json;
    std::string out = "{";
    for (const auto& [name, child] : node.fields) {
      absl::StrAppend(&out, out.size() > 1 ? "," : "", JsonQuoted(name), ":", write(child));
    }
    return out + "}";
  };
  pb::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  if (pb::util::Status parsed = pb::util::JsonStringToMessage(write(root), request, options);
      !parsed.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("query parameters: ", QuoteInput(parsed.message().as_string())));
  }
  return absl::OkStatus();
}

// The request's mesh (the `mesh` field of queries, `name` of GetMesh, DeleteMesh, ...).
const pb::FieldDescriptor* MeshField(const pb::Descriptor* type) {
  for (const char* name : {"mesh", "name"}) {
    const pb::FieldDescriptor* field = type->FindFieldByName(name);
    if (field != nullptr && field->type() == pb::FieldDescriptor::TYPE_STRING &&
        !field->is_repeated()) {
      return field;
    }
  }
  return nullptr;
}

// With Accept: application/geo+json, the geometry methods answer as ExportGis does (RFC 7946
// GeoJSON): the request becomes the ExportGisRequest of the same points, levels and options.
struct GeoJsonProduct {
  const char* method;
  const char* product;
};
constexpr GeoJsonProduct kGeoJsonProducts[] = {
    {"ComputeIsolines", "GIS_PRODUCT_ISOCHRONES"}, {"ComputeVoronoi", "GIS_PRODUCT_VORONOI"},
    {"ComputeDelaunay", "GIS_PRODUCT_DELAUNAY"},   {"FindShortestPath", "GIS_PRODUCT_PATH"},
    {"EstimateDistances", "GIS_PRODUCT_POINTS"},
};

// The ExportGisRequest of a geometry request: its mesh, sources (or `from`), points (or `to`),
// levels, count, options and max_snap, copied field by field (by reflection).
std::unique_ptr<pb::Message> AsExportGis(const pb::Message& request, const char* product) {
  const pb::Descriptor* gis_type = Service().FindMethodByName("ExportGis")->input_type();
  std::unique_ptr<pb::Message> gis = NewMessage(gis_type);
  const pb::Reflection& in = *request.GetReflection();
  const pb::Reflection& out = *gis->GetReflection();
  for (const auto& [from, to] :
       std::vector<std::pair<std::string, std::string>>{{"mesh", "mesh"},
                                                        {"sources", "sources"},
                                                        {"from", "sources"},
                                                        {"points", "points"},
                                                        {"to", "points"},
                                                        {"levels", "levels"},
                                                        {"count", "count"},
                                                        {"options", "options"},
                                                        {"max_snap", "max_snap"}}) {
    const pb::FieldDescriptor* src = request.GetDescriptor()->FindFieldByName(from);
    const pb::FieldDescriptor* dst = gis_type->FindFieldByName(to);
    if (src == nullptr || dst == nullptr) continue;
    if (src->is_repeated()) {
      for (int k = 0; k < in.FieldSize(request, src); ++k) {
        if (src->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE) {
          out.AddMessage(gis.get(), dst)->CopyFrom(in.GetRepeatedMessage(request, src, k));
        } else {  // levels
          out.AddDouble(gis.get(), dst, in.GetRepeatedDouble(request, src, k));
        }
      }
    } else if (src->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE) {
      if (!in.HasField(request, src)) continue;
      if (dst->is_repeated()) {  // from, to: the one source, the one point
        out.AddMessage(gis.get(), dst)->CopyFrom(in.GetMessage(request, src));
      } else {
        out.MutableMessage(gis.get(), dst)->CopyFrom(in.GetMessage(request, src));
      }
    } else if (src->cpp_type() == pb::FieldDescriptor::CPPTYPE_STRING) {
      out.SetString(gis.get(), dst, in.GetString(request, src));
    } else if (src->cpp_type() == pb::FieldDescriptor::CPPTYPE_INT32) {
      out.SetInt32(gis.get(), dst, in.GetInt32(request, src));
    } else if (src->cpp_type() == pb::FieldDescriptor::CPPTYPE_DOUBLE &&
               (!src->has_presence() || in.HasField(request, src))) {
      out.SetDouble(gis.get(), dst, in.GetDouble(request, src));
    }
  }
  out.SetEnumValue(
      gis.get(), gis_type->FindFieldByName("product"),
      gis_type->FindFieldByName("product")->enum_type()->FindValueByName(product)->number());
  return gis;
}

}  // namespace

bool IsUploadRequest(const std::string& method, const std::string& path) {
  return method == "POST" && (path == kCollection || path == absl::StrCat(kCollection, "/"));
}

bool IsUploadMediaType(const std::string& content_type) {
  const std::string type = BareMediaType(content_type);
  return !type.empty() && type.find('/') != std::string::npos && type != "text/plain" &&
         type != "application/x-www-form-urlencoded" && type != "multipart/form-data" &&
         type != "application/json";
}

absl::StatusOr<HttpCall> RouteHttpRequest(const HttpRequest& request) {
  const pb::ServiceDescriptor& service = Service();
  auto no_route = [&] {
    return absl::NotFoundError(absl::StrCat(
        request.method, " ", QuoteInput(request.path),
        ": no such route (GET /v1/meshes, POST /v1/meshes, GET or DELETE /v1/meshes/{id}, POST "
        "/v1/meshes/{id}:{method})"));
  };
  auto wrong_method = [&](const char* allowed) {
    return absl::UnimplementedError(
        absl::StrCat(request.method, " ", QuoteInput(request.path), ": use ", allowed));
  };
  if (!absl::StartsWith(request.path, kCollection)) return no_route();
  std::string rest = request.path.substr(sizeof(kCollection) - 1);
  if (rest == "/") rest.clear();

  // Query parameters: `timeout`, then the request's fields.
  HttpCall call;
  std::map<std::string, std::string> params;
  for (absl::string_view pair : absl::StrSplit(request.query, '&', absl::SkipEmpty())) {
    const size_t eq = pair.find('=');
    const std::string key = PercentDecode(pair.substr(0, eq));
    const std::string value =
        eq == absl::string_view::npos ? "" : PercentDecode(pair.substr(eq + 1));
    if (key == "timeout") {
      absl::StatusOr<double> seconds = ParseTimeoutSeconds(value, false, "query parameter timeout");
      if (!seconds.ok()) return seconds.status();
      call.timeout_seconds = *seconds;
      continue;
    }
    if (!params.emplace(key, value).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("query parameter ", QuoteInput(key), ": given twice"));
    }
  }

  std::string mesh, verb;
  const pb::MethodDescriptor* method = nullptr;
  if (rest.empty()) {  // the collection
    if (request.method == "GET") {
      method = service.FindMethodByName("ListMeshes");
    } else if (IsUploadRequest(request.method, request.path)) {
      method = service.FindMethodByName("CreateMesh");
    } else {
      return wrong_method("GET (list) or POST (upload)");
    }
  } else {
    if (rest[0] != '/' || rest.find('/', 1) != std::string::npos) return no_route();
    const size_t colon = rest.find(':');
    mesh = rest.substr(1, colon == std::string::npos ? std::string::npos : colon - 1);
    if (mesh.empty()) return no_route();
    if (colon == std::string::npos) {
      if (request.method == "GET") {
        method = service.FindMethodByName("GetMesh");
      } else if (request.method == "DELETE") {
        method = service.FindMethodByName("DeleteMesh");
      } else {
        return wrong_method("GET or DELETE");
      }
    } else {
      verb = rest.substr(colon + 1);
      for (int m = 0; m < service.method_count(); ++m) {
        const pb::MethodDescriptor* candidate = service.method(m);
        if (LowerCamel(candidate->name()) == verb && !candidate->client_streaming() &&
            MeshField(candidate->input_type()) != nullptr) {
          method = candidate;
        }
      }
      if (method == nullptr) return no_route();
      if (request.method != "POST") return wrong_method("POST");
    }
  }
  call.method = method;
  call.grpc_method = absl::StrCat("/", service.full_name(), "/", method->name());
  std::unique_ptr<pb::Message> message = NewMessage(method->input_type());

  if (method->client_streaming()) {  // CreateMesh: the metadata from the query, the file follows
    if (!IsUploadMediaType(request.content_type)) {
      return absl::FailedPreconditionError(absl::StrCat(
          "Content-Type ", QuoteInput(request.content_type),
          ": an upload's body is the file (application/octet-stream, image/tiff, ...)"));
    }
    const pb::FieldDescriptor* metadata = method->input_type()->FindFieldByName("metadata");
    pb::Message* fields = message->GetReflection()->MutableMessage(message.get(), metadata);
    if (absl::Status set = SetFieldsFromQuery(params, fields); !set.ok()) return set;
    call.mesh_key = fields->GetReflection()->GetString(
        *fields, fields->GetDescriptor()->FindFieldByName("expected_mesh_id"));
    if (request.content_length >= 0) {  // the server refuses an upload over its limit up front
      fields->GetReflection()->SetUInt64(fields,
                                         fields->GetDescriptor()->FindFieldByName("total_bytes"),
                                         static_cast<uint64_t>(request.content_length));
    }
    call.upload = true;
  } else if (request.method == "POST") {
    if (!params.empty()) {
      return absl::InvalidArgumentError(absl::StrCat("query parameter ", params.begin()->first,
                                                     ": a POST's fields go in its JSON body"));
    }
    if (BareMediaType(request.content_type) != "application/json") {
      return absl::FailedPreconditionError(
          absl::StrCat("Content-Type ", QuoteInput(request.content_type),
                       ": the body must be application/json (the request message's JSON)"));
    }
    pb::util::JsonParseOptions options;
    options.ignore_unknown_fields = false;
    const std::string body = absl::StripAsciiWhitespace(request.body).empty() ? "{}" : request.body;
    if (pb::util::Status parsed = pb::util::JsonStringToMessage(body, message.get(), options);
        !parsed.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("body: not a ", method->input_type()->full_name(),
                       " in JSON: ", QuoteInput(parsed.message().as_string())));
    }
  } else if (absl::Status set = SetFieldsFromQuery(params, message.get()); !set.ok()) {
    return set;
  }
  if (!mesh.empty()) {
    const pb::FieldDescriptor* field = MeshField(method->input_type());
    const std::string name = absl::StrCat("meshes/", mesh);
    const std::string given = message->GetReflection()->GetString(*message, field);
    if (!given.empty() && given != name && given != mesh) {
      return absl::InvalidArgumentError(
          absl::StrCat("body: ", field->json_name(), " ", QuoteInput(given),
                       " differs from the path's mesh; leave it out"));
    }
    message->GetReflection()->SetString(message.get(), field, name);
    call.mesh_key = mesh;
  }
  if (absl::StrContains(absl::AsciiStrToLower(request.accept), "application/geo+json")) {
    for (const GeoJsonProduct& geo : kGeoJsonProducts) {
      if (method->name() != geo.method) continue;
      message = AsExportGis(*message, geo.product);
      method = service.FindMethodByName("ExportGis");
      call.method = method;
      call.grpc_method = absl::StrCat("/", service.full_name(), "/", method->name());
      break;
    }
  }
  call.request = message->SerializeAsString();
  if (method->name() == "ExportGis") {
    call.answer = HttpAnswer::kFile;
  } else if (method->server_streaming() &&
             absl::StrContains(absl::AsciiStrToLower(request.accept), "application/x-ndjson")) {
    call.answer = HttpAnswer::kNdjson;
  }
  return call;
}

std::string UploadChunkMessage(const HttpCall& call, const std::string& bytes) {
  std::unique_ptr<pb::Message> message = NewMessage(call.method->input_type());
  message->GetReflection()->SetString(message.get(),
                                      call.method->input_type()->FindFieldByName("chunk"), bytes);
  return message->SerializeAsString();
}

std::string MessageToHttpJson(const pb::Message& message) {
  pb::util::JsonPrintOptions options;
  options.always_print_primitive_fields = true;
  std::string json;
  if (!pb::util::MessageToJsonString(message, &json, options).ok()) return "{}";
  return json;
}

HttpAnswerBuilder::HttpAnswerBuilder(const HttpCall& call, uint64_t max_bytes)
    : call_(call), max_bytes_(max_bytes) {}

absl::Status HttpAnswerBuilder::Add(const std::string& bytes, std::string* out) {
  out->clear();
  const pb::Descriptor* type = call_.method->output_type();
  std::unique_ptr<pb::Message> message = NewMessage(type);
  if (!message->ParseFromString(bytes)) {
    return absl::InternalError(absl::StrCat("a ", type->full_name(), " that does not parse"));
  }
  const pb::Reflection& reflection = *message->GetReflection();
  ++messages_;
  switch (call_.answer) {
    case HttpAnswer::kNdjson:
      *out = MessageToHttpJson(*message) + "\n";
      return absl::OkStatus();
    case HttpAnswer::kFile:
    case HttpAnswer::kJson:
      break;
  }
  bytes_ += bytes.size();
  if (bytes_ > max_bytes_) {
    const bool ndjson = call_.answer == HttpAnswer::kJson && call_.method->server_streaming();
    return absl::ResourceExhaustedError(
        absl::StrCat("the answer exceeds --http_max_response_bytes=", max_bytes_,
                     ndjson ? "; ask for it as NDJSON (Accept: application/x-ndjson), or over gRPC"
                            : "; ask for it over gRPC"));
  }
  if (call_.answer == HttpAnswer::kFile) {  // the file whole, so an error is never a cut file
    if (messages_ == 1) {
      file_media_type_ = reflection.GetString(*message, type->FindFieldByName("media_type"));
    }
    file_ += reflection.GetString(*message, type->FindFieldByName("data"));
    return absl::OkStatus();
  }
  const pb::FieldDescriptor* offset = type->FindFieldByName("offset");
  if (assembled_ == nullptr) {
    assembled_ = std::move(message);
    if (offset != nullptr) first_offset_ = reflection.GetUInt64(*assembled_, offset);
  } else {
    assembled_->MergeFrom(*message);  // repeated fields concatenate, in stream order
  }
  // Chunks continue at their own offset; the whole answer starts where the first chunk did.
  if (offset != nullptr) reflection.SetUInt64(assembled_.get(), offset, first_offset_);
  return absl::OkStatus();
}

std::string HttpAnswerBuilder::Finish() {
  if (call_.answer == HttpAnswer::kFile) return std::move(file_);
  if (call_.answer != HttpAnswer::kJson) return "";
  if (assembled_ == nullptr) assembled_ = NewMessage(call_.method->output_type());
  return MessageToHttpJson(*assembled_);
}

std::string HttpAnswerBuilder::media_type() const {
  switch (call_.answer) {
    case HttpAnswer::kNdjson:
      return "application/x-ndjson";
    case HttpAnswer::kFile:
      return file_media_type_.empty() ? "application/octet-stream" : file_media_type_;
    case HttpAnswer::kJson:
      break;
  }
  return "application/json";
}

int HttpStatusOf(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK:
      return 200;
    case grpc::StatusCode::CANCELLED:
      return 499;
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::FAILED_PRECONDITION:
    case grpc::StatusCode::OUT_OF_RANGE:
      return 400;
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return 504;
    case grpc::StatusCode::NOT_FOUND:
      return 404;
    case grpc::StatusCode::ALREADY_EXISTS:
    case grpc::StatusCode::ABORTED:
      return 409;
    case grpc::StatusCode::PERMISSION_DENIED:
      return 403;
    case grpc::StatusCode::UNAUTHENTICATED:
      return 401;
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      return 429;
    case grpc::StatusCode::UNIMPLEMENTED:
      return 501;
    case grpc::StatusCode::UNAVAILABLE:
      return 503;
    default:
      return 500;  // UNKNOWN, INTERNAL, DATA_LOSS
  }
}

std::string ErrorJson(const grpc::Status& status) {
  google::rpc::Status rpc;
  if (status.error_details().empty() || !rpc.ParseFromString(status.error_details())) {
    rpc.Clear();
  }
  rpc.set_code(status.error_code());
  rpc.set_message(status.error_message());
  std::string json;
  if (!pb::util::MessageToJsonString(rpc, &json).ok()) {  // a detail of a type not linked in
    rpc.clear_details();
    json = MessageToHttpJson(rpc);
  }
  return json;
}

absl::StatusOr<double> ParseTimeoutSeconds(const std::string& text, bool grpc_form,
                                           const std::string& what) {
  auto bad = [&] {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " ", QuoteInput(text), ": not a duration (",
                     grpc_form ? "gRPC's form: 30S, 500m, 2M" : "30s, 1.5s, 500ms, 2m", ")"));
  };
  double seconds = 0;
  if (grpc_form) {
    static const std::map<char, double> kUnits = {{'H', 3600.0}, {'M', 60.0}, {'S', 1.0},
                                                  {'m', 1e-3},   {'u', 1e-6}, {'n', 1e-9}};
    uint64_t count = 0;
    if (text.size() < 2 || text.size() > 9 || kUnits.count(text.back()) == 0 ||
        !absl::SimpleAtoi(text.substr(0, text.size() - 1), &count) ||
        !std::isdigit(static_cast<unsigned char>(text[0]))) {
      return bad();
    }
    seconds = static_cast<double>(count) * kUnits.at(text.back());
  } else {
    absl::Duration duration;
    if (!absl::ParseDuration(text, &duration) || duration < absl::ZeroDuration() ||
        duration == absl::InfiniteDuration()) {
      return bad();
    }
    seconds = absl::ToDoubleSeconds(duration);
  }
  if (!(seconds > 0)) return bad();
  return seconds;
}

}  // namespace geodex::server
