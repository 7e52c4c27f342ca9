#pragma once

// The data directory: one file per mesh, written atomically, so a restart loses nothing and a crash
// (even kill -9 mid-upload) never leaves a partial mesh visible.
//
// Layout: DIR/meshes/<mesh_id>.gdxs. File format (integers little-endian):
//   bytes 0..7   magic "GDXSTOR1"
//   uint32       format version (2; version 1 files are still read, see mesh_file_header.h)
//   uint32       header length H, then H bytes: the MeshRecord (id, aliases, pin, counts, memory,
//                create time, summary) in storage's private layout (mesh_file_header.h)
//   uint64       payload length P, then P bytes: the canonical mesh encoding whose SHA-256 is the
//                mesh id (geodex.proto, Mesh.name)
//   32 bytes     SHA-256 of every byte before it
// Writes go to a unique temporary file in the same directory, are fsync'ed, renamed over the final
// name and the directory is fsync'ed. Temporary files left by a crash are removed at start.

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "geodex/mesh_data.h"
#include "mesh_record.h"

namespace geodex::server {

class MeshDisk {
 public:
  // What Open found.
  struct IndexEntry {
    std::string id;
    MeshRecord header;
  };
  struct Skipped {
    std::string path;
    std::string reason;
  };
  struct Index {
    std::vector<IndexEntry> meshes;
    std::vector<Skipped> skipped;  // corrupt, truncated or misnamed files (left in place)
    std::vector<std::string> removed_temporaries;
    bool fresh = false;  // the directory had never been initialised
  };

  // Creates DIR/meshes if needed, removes stale temporaries and reads every file's header
  // (cheap: the payload is checked when the mesh is loaded). Errors: the directory cannot be
  // created or read.
  static absl::StatusOr<MeshDisk> Open(const std::string& dir, Index* index);

  // Writes a mesh atomically (replacing an existing file of the same id). ResourceExhausted when
  // the disk is full, Internal/PermissionDenied for other I/O errors; on error nothing is left.
  absl::Status Write(const MeshRecord& header, const std::string& canonical) const;
  // Reads and verifies a mesh file: its checksum, its header and that the payload's SHA-256 is
  // its id. DataLoss naming the file when it does not verify.
  absl::Status Read(const std::string& id, MeshRecord* header, std::string* canonical) const;
  // Rewrites the header of a stored mesh (a new alias), keeping the payload.
  absl::Status UpdateHeader(const MeshRecord& header) const;
  absl::Status Remove(const std::string& id) const;

  const std::string& dir() const { return dir_; }
  std::string PathOf(const std::string& id) const;

 private:
  explicit MeshDisk(std::string dir) : dir_(std::move(dir)) {}
  std::string dir_;  // DIR/meshes
};

}  // namespace geodex::server
