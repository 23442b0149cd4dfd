// Checks of the DDS Security files with OpenSSL, before a vendor sees them (security.hpp).
#include "crane/transport/security.hpp"

#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <ctime>
#include <filesystem>
#include <memory>
#include <string>

namespace crane::transport {
namespace {

struct Free {
  void operator()(BIO* p) const noexcept { BIO_free_all(p); }
  void operator()(X509* p) const noexcept { X509_free(p); }
  void operator()(EVP_PKEY* p) const noexcept { EVP_PKEY_free(p); }
  void operator()(PKCS7* p) const noexcept { PKCS7_free(p); }
  void operator()(X509_STORE* p) const noexcept { X509_STORE_free(p); }
};
template <class T>
using Owned = std::unique_ptr<T, Free>;

std::string openssl_error() {
  const unsigned long code = ERR_get_error();
  ERR_clear_error();
  if (code == 0) return "no OpenSSL detail";
  char text[256];
  ERR_error_string_n(code, text, sizeof(text));
  return text;
}

[[noreturn]] void refuse(const std::string& file, const std::string& why) {
  throw SecurityError("DDS Security file " + file + ": " + why);
}

Owned<BIO> open_file(const std::string& file) {
  if (!std::filesystem::is_regular_file(file)) refuse(file, "does not exist (run deploy/crane security init)");
  Owned<BIO> bio(BIO_new_file(file.c_str(), "r"));
  if (!bio) refuse(file, "cannot be read: " + openssl_error());
  return bio;
}

Owned<X509> read_certificate(const std::string& file) {
  auto bio = open_file(file);
  Owned<X509> cert(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr));
  if (!cert) refuse(file, "is not a PEM certificate: " + openssl_error());
  return cert;
}

std::string asn1_text(const ASN1_TIME* time) {
  Owned<BIO> out(BIO_new(BIO_s_mem()));
  ASN1_TIME_print(out.get(), time);
  char* data = nullptr;
  const long n = BIO_get_mem_data(out.get(), &data);
  return std::string(data, static_cast<std::size_t>(n));
}

void check_validity(const std::string& file, X509* cert) {
  if (X509_cmp_current_time(X509_get0_notBefore(cert)) > 0) {
    refuse(file, "certificate not yet valid: notBefore " + asn1_text(X509_get0_notBefore(cert)));
  }
  if (X509_cmp_current_time(X509_get0_notAfter(cert)) < 0) {
    refuse(file, "certificate expired: notAfter " + asn1_text(X509_get0_notAfter(cert)));
  }
}

std::string subject_of(X509* cert) {
  Owned<BIO> out(BIO_new(BIO_s_mem()));
  X509_NAME_print_ex(out.get(), X509_get_subject_name(cert), 0, XN_FLAG_RFC2253);
  char* data = nullptr;
  const long n = BIO_get_mem_data(out.get(), &data);
  return std::string(data, static_cast<std::size_t>(n));
}

/// The content of an S/MIME signed file, verified against `ca` (signature and signer chain).
std::string verified_content(const std::string& file, X509* ca) {
  auto bio = open_file(file);
  BIO* content_raw = nullptr;
  Owned<PKCS7> p7(SMIME_read_PKCS7(bio.get(), &content_raw));
  Owned<BIO> content(content_raw);
  if (!p7) refuse(file, "is not an S/MIME signed document: " + openssl_error());
  Owned<X509_STORE> store(X509_STORE_new());
  X509_STORE_add_cert(store.get(), ca);
  Owned<BIO> out(BIO_new(BIO_s_mem()));
  // The signer need not be fit for S/MIME purposes (a DDS CA signs it): PKCS7_NOVERIFY would skip
  // the chain; instead the purpose check is relaxed by checking the chain against the CA alone.
  X509_STORE_set_purpose(store.get(), X509_PURPOSE_ANY);
  if (PKCS7_verify(p7.get(), nullptr, store.get(), content.get(), out.get(), PKCS7_TEXT) != 1) {
    refuse(file, "signature does not verify against the CA (tampered with, or signed by another CA): " +
                     openssl_error());
  }
  char* data = nullptr;
  const long n = BIO_get_mem_data(out.get(), &data);
  return std::string(data, static_cast<std::size_t>(n));
}

std::string element(const std::string& xml, const std::string& name) {
  const auto open = xml.find("<" + name + ">");
  const auto close = xml.find("</" + name + ">");
  if (open == std::string::npos || close == std::string::npos || close < open) return {};
  const auto start = open + name.size() + 2;
  return xml.substr(start, close - start);
}

/// "YYYY-MM-DDTHH:MM:SS" (UTC) -> seconds since the epoch; -1 when malformed.
std::time_t parse_utc(const std::string& text) {
  std::tm tm{};
  if (std::sscanf(text.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour,
                  &tm.tm_min, &tm.tm_sec) != 6) {
    return -1;
  }
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return timegm(&tm);
}

std::string absolute_path(const std::filesystem::path& p) { return std::filesystem::absolute(p).lexically_normal().string(); }

}  // namespace

std::string certificate_subject(const std::string& certificate_file) {
  auto cert = read_certificate(certificate_file);
  return subject_of(cert.get());
}

SecurityFiles security_files(const std::string& directory, const std::string& identity) {
  if (identity.empty() || identity.find('/') != std::string::npos) {
    throw std::invalid_argument("security identity '" + identity + "' must be a folder name of " + directory);
  }
  const std::filesystem::path dir(directory);
  if (!std::filesystem::is_directory(dir / identity)) {
    throw SecurityError("DDS Security: no identity '" + identity + "' in " + directory + " (no folder " +
                        absolute_path(dir / identity) + "; deploy/crane security init makes one per process and tool role)");
  }
  SecurityFiles files;
  files.identity_ca = absolute_path(dir / "ca" / "ca.pem");
  files.permissions_ca = files.identity_ca;
  files.governance = absolute_path(dir / "governance.p7s");
  files.certificate = absolute_path(dir / identity / "cert.pem");
  files.private_key = absolute_path(dir / identity / "key.pem");
  files.permissions = absolute_path(dir / identity / "permissions.p7s");

  auto ca = read_certificate(files.identity_ca);
  check_validity(files.identity_ca, ca.get());
  auto cert = read_certificate(files.certificate);
  Owned<EVP_PKEY> ca_key(X509_get_pubkey(ca.get()));
  if (!ca_key || X509_verify(cert.get(), ca_key.get()) != 1) {
    ERR_clear_error();
    refuse(files.certificate, "not signed by the CA " + files.identity_ca);
  }
  check_validity(files.certificate, cert.get());
  {
    auto bio = open_file(files.private_key);
    Owned<EVP_PKEY> key(PEM_read_bio_PrivateKey(bio.get(), nullptr, nullptr, nullptr));
    if (!key) refuse(files.private_key, "is not an unencrypted PEM private key: " + openssl_error());
    if (X509_check_private_key(cert.get(), key.get()) != 1) {
      ERR_clear_error();
      refuse(files.private_key, "does not match the certificate " + files.certificate);
    }
  }
  (void)verified_content(files.governance, ca.get());
  const std::string permissions = verified_content(files.permissions, ca.get());
  const std::string subject = subject_of(cert.get());
  const std::string granted = element(permissions, "subject_name");
  if (granted != subject) {
    refuse(files.permissions, "grants subject '" + granted + "', the certificate " + files.certificate + " is '" +
                                  subject + "'");
  }
  const std::time_t now = std::time(nullptr);
  const std::string not_before = element(permissions, "not_before");
  const std::string not_after = element(permissions, "not_after");
  const std::time_t begin = parse_utc(not_before);
  const std::time_t end = parse_utc(not_after);
  if (begin < 0 || end < 0) refuse(files.permissions, "has no readable validity (not_before/not_after)");
  if (now < begin) refuse(files.permissions, "permissions not yet valid: not_before " + not_before);
  if (now > end) refuse(files.permissions, "permissions expired: not_after " + not_after);
  return files;
}

}  // namespace crane::transport
