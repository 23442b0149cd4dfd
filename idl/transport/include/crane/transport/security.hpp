#pragma once
// DDS Security files of one participant (OMG DDS Security 1.1: builtin PKI-DH authentication,
// Permissions access control, AES-GCM-GMAC cryptography), in the layout that
// `deploy/crane security init` writes (docs/deployment.md, "Security"):
//
//   DIR/ca/ca.pem                    identity CA and permissions CA
//   DIR/governance.p7s               governance, S/MIME signed by the CA
//   DIR/<identity>/cert.pem          the identity's certificate, signed by the CA
//   DIR/<identity>/key.pem           its private key
//   DIR/<identity>/permissions.p7s   its permissions, S/MIME signed by the CA
//
// Both vendors are configured from the same files (fast_dds_backend.cpp, cyclone_dds_backend.cpp).
// Neither vendor's error names the file it refused (Fast DDS 2.9 returns no participant, Cyclone
// 0.10 "Error"), so security_files() checks them first, with OpenSSL, and names the file.

#include <stdexcept>
#include <string>

namespace crane::transport {

/// A security file that is missing, unreadable, tampered with, expired or not for this identity.
/// what() names the file and what is wrong with it.
class SecurityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Absolute paths of one participant's security files.
struct SecurityFiles {
  std::string identity_ca;     // PEM certificate of the identity CA
  std::string permissions_ca;  // PEM certificate of the permissions CA (the same CA here)
  std::string governance;      // S/MIME signed governance document
  std::string certificate;     // PEM certificate of the identity
  std::string private_key;     // PEM private key of the identity (unencrypted)
  std::string permissions;     // S/MIME signed permissions document of the identity
};

/// The files of `identity` in `directory` (layout above), checked: each exists and parses; the
/// certificate is signed by the CA, valid now (notBefore <= now <= notAfter) and matches the key;
/// the governance and the permissions carry a valid S/MIME signature of the CA over their content
/// (any change to a signed file breaks it); the permissions' subject_name is the certificate's
/// subject and their validity includes now. Throws SecurityError naming the file and the reason;
/// std::invalid_argument for an empty identity or one with a '/'.
[[nodiscard]] SecurityFiles security_files(const std::string& directory, const std::string& identity);

/// The certificate's subject as both vendors compare it with a permissions grant (RFC 2253, e.g.
/// "CN=plant,O=crane"). Throws SecurityError naming the file when it cannot be read.
[[nodiscard]] std::string certificate_subject(const std::string& certificate_file);

}  // namespace crane::transport
