// SHA-256 through OpenSSL's EVP interface: blobs are named by the hash of their bytes, and the
// hash is computed while the bytes stream in, so that an upload is never held whole in memory.
#pragma once

#include <memory>
#include <string>
#include <string_view>

struct evp_md_ctx_st;

namespace parapm::service {

// One running hash. Not thread-safe; movable, not copyable.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(Sha256&&) noexcept;
  Sha256& operator=(Sha256&&) noexcept;

  void update(std::string_view bytes);
  // Finishes the hash and returns it as 64 lowercase hex characters. Calling hex() again
  // returns the same value; update() after hex() is a bug and throws kInternal.
  std::string hex();

 private:
  struct Free {
    void operator()(evp_md_ctx_st* ctx) const;
  };
  std::unique_ptr<evp_md_ctx_st, Free> ctx_;
  std::string hex_;  // empty until finished
};

std::string sha256_hex(std::string_view bytes);

// True when `text` is 64 lowercase hex characters: the only form a blob name may take, which
// also rules out any path trick ("../x", "/", "a/b") before a name meets the file system.
bool is_sha256_hex(std::string_view text);

}  // namespace parapm::service
