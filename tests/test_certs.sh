#!/bin/sh
# Generates throw-away TLS material for the service tests with the openssl CLI:
#   ca.pem / ca.key           a self-signed test CA
#   server.pem / server.key   server certificate, SAN DNS:localhost, IP:127.0.0.1, IP:::1
#   client.pem / client.key   client certificate (extendedKeyUsage clientAuth) for mutual TLS
#   other-ca.pem, other-client.pem / other-client.key   a second CA and a client it signed (must be rejected)
# Usage: tests/test_certs.sh DIR   (DIR is created; existing files are overwritten)
# EC P-256 keys: generated in milliseconds. Valid for 2 days; never use outside tests.
set -eu
dir=${1:?usage: test_certs.sh DIR}
mkdir -p "$dir"
cd "$dir"

key() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1" 2>/dev/null; }

ca() {  # ca NAME SUBJECT
  key "$1.key"
  openssl req -x509 -new -key "$1.key" -sha256 -days 2 -subj "$2" \
    -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,keyCertSign,cRLSign" \
    -out "$1.pem" 2>/dev/null
}

leaf() {  # leaf NAME CA SUBJECT EXTFILE-CONTENT
  key "$1.key"
  openssl req -new -key "$1.key" -subj "$3" -out "$1.csr" 2>/dev/null
  printf '%s\n' "$4" > "$1.ext"
  openssl x509 -req -in "$1.csr" -CA "$2.pem" -CAkey "$2.key" -CAcreateserial -days 2 -sha256 \
    -extfile "$1.ext" -out "$1.pem" 2>/dev/null
  rm -f "$1.csr" "$1.ext"
}

ca ca "/CN=tubepick test CA"
leaf server ca "/CN=localhost" "basicConstraints=CA:FALSE
keyUsage=critical,digitalSignature,keyEncipherment
extendedKeyUsage=serverAuth
subjectAltName=DNS:localhost,IP:127.0.0.1,IP:::1"
leaf client ca "/CN=tubepick test cell" "basicConstraints=CA:FALSE
keyUsage=critical,digitalSignature
extendedKeyUsage=clientAuth"

ca other-ca "/CN=some other CA"
leaf other-client other-ca "/CN=stranger" "basicConstraints=CA:FALSE
keyUsage=critical,digitalSignature
extendedKeyUsage=clientAuth"
rm -f ./*.srl
