#include "mesh_disk.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "geodex/mesh_id.h"
#include "mesh_file_header.h"

namespace geodex::server {
namespace {

constexpr char kMagic[8] = {'G', 'D', 'X', 'S', 'T', 'O', 'R', '1'};
constexpr char kSuffix[] = ".gdxs";
constexpr char kTempMarker[] = ".tmp.";
// A header is a few hundred bytes; anything larger means a corrupt length.
constexpr uint32_t kMaxHeaderBytes = 1 << 20;

void PutU32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void PutU64(std::string* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
uint64_t GetLE(const char* p, int bytes) {
  uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<uint8_t>(p[i]);
  return v;
}

absl::Status ErrnoStatus(int err, const std::string& what) {
  std::string message = absl::StrCat(what, ": ", std::strerror(err));
  if (err == ENOSPC || err == EDQUOT) {
    return absl::ResourceExhaustedError(absl::StrCat("data directory full: ", message));
  }
  if (err == EACCES || err == EPERM || err == EROFS) return absl::PermissionDeniedError(message);
  return absl::InternalError(message);
}

absl::Status WriteAll(int fd, const std::string& bytes, const std::string& path) {
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return ErrnoStatus(errno, absl::StrCat("writing ", path));
    }
    done += static_cast<size_t>(n);
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open"));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return absl::DataLossError(absl::StrCat(path, ": read error"));
  return bytes;
}

struct Parsed {
  MeshRecord header;
  size_t payload_offset = 0;
  size_t payload_size = 0;
};

// Checks the framing (magic, version, lengths adding up to the file size) and parses the header.
// With `verify`, also the trailing checksum. Errors are DataLoss with the reason.
absl::StatusOr<Parsed> ParseFile(const std::string& bytes, bool verify) {
  Parsed out;
  if (bytes.size() < 8 + 4 + 4 + 8 + 32) return absl::DataLossError("truncated (too short)");
  if (std::memcmp(bytes.data(), kMagic, 8) != 0)
    return absl::DataLossError("not a geodex mesh file");
  const uint32_t version = static_cast<uint32_t>(GetLE(bytes.data() + 8, 4));
  const uint64_t header_size = GetLE(bytes.data() + 12, 4);
  if (header_size > kMaxHeaderBytes || 16 + header_size + 8 + 32 > bytes.size()) {
    return absl::DataLossError("truncated or corrupt header length");
  }
  const uint64_t payload_size = GetLE(bytes.data() + 16 + header_size, 8);
  if (16 + header_size + 8 + payload_size + 32 != bytes.size()) {
    return absl::DataLossError(absl::StrCat("truncated: the file has ", bytes.size(),
                                            " bytes, its lengths say ",
                                            16 + header_size + 8 + payload_size + 32));
  }
  absl::StatusOr<MeshRecord> header =
      DecodeMeshFileHeader(version, absl::string_view(bytes).substr(16, header_size));
  if (!header.ok()) return header.status();
  out.header = *std::move(header);
  out.payload_offset = 16 + header_size + 8;
  out.payload_size = payload_size;
  if (verify) {
    Sha256 sha;
    sha.Update(bytes.data(), bytes.size() - 32);
    std::array<uint8_t, 32> sum = sha.Finish();
    if (std::memcmp(sum.data(), bytes.data() + bytes.size() - 32, 32) != 0) {
      return absl::DataLossError("checksum mismatch (corrupt file)");
    }
  }
  return out;
}

// Reads only the first bytes of a file (magic, version, header) plus its size: the index check.
absl::StatusOr<MeshRecord> ReadHeaderOnly(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return absl::DataLossError("cannot open");
  const uint64_t size = static_cast<uint64_t>(in.tellg());
  in.seekg(0);
  char head[16];
  if (size < 16 + 8 + 32 || !in.read(head, 16)) return absl::DataLossError("truncated (too short)");
  if (std::memcmp(head, kMagic, 8) != 0) return absl::DataLossError("not a geodex mesh file");
  const uint32_t version = static_cast<uint32_t>(GetLE(head + 8, 4));
  const uint64_t header_size = GetLE(head + 12, 4);
  if (header_size > kMaxHeaderBytes || 16 + header_size + 8 + 32 > size) {
    return absl::DataLossError("truncated or corrupt header length");
  }
  std::string header(header_size + 8, '\0');
  if (!in.read(header.data(), static_cast<std::streamsize>(header.size()))) {
    return absl::DataLossError("truncated header");
  }
  const uint64_t payload_size = GetLE(header.data() + header_size, 8);
  if (16 + header_size + 8 + payload_size + 32 != size) {
    return absl::DataLossError(absl::StrCat("truncated: the file has ", size,
                                            " bytes, its lengths say ",
                                            16 + header_size + 8 + payload_size + 32));
  }
  return DecodeMeshFileHeader(version, absl::string_view(header).substr(0, header_size));
}

}  // namespace

std::string MeshDisk::PathOf(const std::string& id) const {
  return absl::StrCat(dir_, "/", id, kSuffix);
}

absl::StatusOr<MeshDisk> MeshDisk::Open(const std::string& dir, Index* index) {
  namespace fs = std::filesystem;
  *index = Index();
  const std::string meshes = absl::StrCat(dir, "/meshes");
  std::error_code ec;
  index->fresh = !fs::exists(meshes, ec);
  fs::create_directories(meshes, ec);
  if (ec) return ErrnoStatus(ec.value(), absl::StrCat("creating ", meshes));
  for (fs::directory_iterator it(meshes, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const std::string path = it->path().string();
    if (name.find(kTempMarker) != std::string::npos) {  // a write interrupted by a crash
      fs::remove(it->path(), ec);
      index->removed_temporaries.push_back(path);
      ec.clear();
      continue;
    }
    const std::string id = name.substr(0, name.size() - std::strlen(kSuffix));
    if (!absl::EndsWith(name, kSuffix) || !IsMeshId(id)) {
      index->skipped.push_back({path, "not a mesh file name (<64 hex digits>.gdxs)"});
      continue;
    }
    absl::StatusOr<MeshRecord> header = ReadHeaderOnly(path);
    if (!header.ok()) {
      index->skipped.push_back({path, std::string(header.status().message())});
      continue;
    }
    if (header->id != id) {
      index->skipped.push_back({path, "the header names another mesh"});
      continue;
    }
    index->meshes.push_back({id, *std::move(header)});
  }
  if (ec) return ErrnoStatus(ec.value(), absl::StrCat("reading ", meshes));
  return MeshDisk(meshes);
}

absl::Status MeshDisk::Write(const MeshRecord& header, const std::string& canonical) const {
  const std::string& id = header.id;
  std::string bytes(kMagic, 8);
  PutU32(&bytes, kMeshFileVersion);
  const std::string head = EncodeMeshFileHeader(header);
  PutU32(&bytes, static_cast<uint32_t>(head.size()));
  bytes += head;
  PutU64(&bytes, canonical.size());
  bytes += canonical;
  Sha256 sha;
  sha.Update(bytes.data(), bytes.size());
  std::array<uint8_t, 32> sum = sha.Finish();
  bytes.append(reinterpret_cast<const char*>(sum.data()), sum.size());

  static std::atomic<uint64_t> counter{0};
  const std::string final_path = PathOf(id);
  const std::string temp_path =
      absl::StrCat(final_path, kTempMarker, ::getpid(), ".", counter.fetch_add(1));
  const int fd = ::open(temp_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return ErrnoStatus(errno, absl::StrCat("creating ", temp_path));
  absl::Status status = WriteAll(fd, bytes, temp_path);
  if (status.ok() && ::fsync(fd) != 0)
    status = ErrnoStatus(errno, absl::StrCat("fsync ", temp_path));
  if (::close(fd) != 0 && status.ok())
    status = ErrnoStatus(errno, absl::StrCat("closing ", temp_path));
  if (status.ok() && ::rename(temp_path.c_str(), final_path.c_str()) != 0) {
    status = ErrnoStatus(errno, absl::StrCat("renaming ", temp_path));
  }
  if (!status.ok()) {
    ::unlink(temp_path.c_str());
    return status;
  }
  // The rename itself must survive a power cut: sync the directory entry.
  const int dir_fd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
  return absl::OkStatus();
}

absl::Status MeshDisk::Read(const std::string& id, MeshRecord* header,
                            std::string* canonical) const {
  // Messages name the mesh, never the server's paths (they reach clients).
  const std::string path = PathOf(id);
  const std::string mesh = absl::StrCat("stored mesh meshes/", id);
  absl::StatusOr<std::string> bytes = ReadWholeFile(path);
  if (!bytes.ok()) return absl::DataLossError(absl::StrCat(mesh, ": its file is missing"));
  absl::StatusOr<Parsed> parsed = ParseFile(*bytes, /*verify=*/true);
  if (!parsed.ok()) {
    return absl::DataLossError(absl::StrCat(mesh, ": ", parsed.status().message()));
  }
  canonical->assign(*bytes, parsed->payload_offset, parsed->payload_size);
  if (Sha256Hex(*canonical) != id) {
    return absl::DataLossError(absl::StrCat(mesh, ": content does not hash to its id"));
  }
  *header = std::move(parsed->header);
  return absl::OkStatus();
}

absl::Status MeshDisk::UpdateHeader(const MeshRecord& header) const {
  MeshRecord old;
  std::string canonical;
  if (absl::Status s = Read(header.id, &old, &canonical); !s.ok()) return s;
  return Write(header, canonical);
}

absl::Status MeshDisk::Remove(const std::string& id) const {
  const std::string path = PathOf(id);
  if (::unlink(path.c_str()) != 0 && errno != ENOENT) {
    return ErrnoStatus(errno, absl::StrCat("removing ", path));
  }
  return absl::OkStatus();
}

}  // namespace geodex::server
