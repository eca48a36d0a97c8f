// digest — SHA-256, the one cryptographic digest of the module store.
//
// Cache keys, the digest of each cached module's bytes and the digest of the
// program a module was built from are all SHA-256 (OpenSSL's EVP interface,
// libcrypto), written as 64 lowercase hex digits. A 64-bit hash is not enough
// where a collision would run one program's module for another.
#pragma once
#include <memory>
#include <string>
#include <string_view>

namespace autumn {

// Incremental: feed pieces, then take the hex digest once.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  void update(std::string_view bytes);
  // A length-prefixed piece ("<size>:<bytes>"): no two sequences of pieces
  // feed the same bytes.
  void piece(std::string_view bytes);
  std::string hex();

 private:
  struct Ctx;
  std::unique_ptr<Ctx> ctx_;
};

std::string sha256_hex(std::string_view bytes);

}  // namespace autumn
