#!/usr/bin/env bash
# geodexd with TLS and bearer tokens, driven by the CLI: a self-signed certificate made here
# (openssl); with --ca and --token-file (or GEODEX_TOKEN) every command works; without a token it
# fails with one line (exit 1) while health stays open; plaintext to the TLS port fails.
# Env: GEODEX, GEODEXD, DATA.
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=localhost \
  -addext subjectAltName=IP:127.0.0.1,DNS:localhost -keyout "$tmp/key.pem" -out "$tmp/cert.pem" \
  >/dev/null 2>&1
check "certificate made" test -s "$tmp/cert.pem"
echo "token-$$-$RANDOM" >"$tmp/token"
start_geodexd "$tmp/server.log" --tls_cert "$tmp/cert.pem" --tls_key "$tmp/key.pem" \
  --auth_token_file "$tmp/token" --shutdown_grace_seconds 5
port=$geodexd_port
check "server started" test -n "$port"
check "startup says tls and tokens" grep -q "security: tls=true bearer_tokens=true" "$tmp/server.log"
S=("$GEODEX" --server "127.0.0.1:$port" --ca "$tmp/cert.pem")

"${S[@]}" --token-file "$tmp/token" distances "$DATA/knight.off" --sources 0 >"$tmp/remote.txt"
check "distances with TLS and a token: exit 0" test $? -eq 0
"$GEODEX" distances "$DATA/knight.off" --sources 0 >"$tmp/local.txt"
check "same answer as local mode" cmp -s "$tmp/local.txt" "$tmp/remote.txt"
GEODEX_TOKEN=$(cat "$tmp/token") "${S[@]}" mesh list >/dev/null
check "GEODEX_TOKEN works too" test $? -eq 0
"${S[@]}" distances "$DATA/knight.off" --sources 0 >/dev/null 2>"$tmp/err.txt"
check "no token: exit 1" test $? -eq 1
check "no token: one line naming the bearer token" bash -c "test \$(wc -l <'$tmp/err.txt') -eq 1 && grep -q 'bearer token' '$tmp/err.txt'"
echo wrong >"$tmp/wrong"
"${S[@]}" --token-file "$tmp/wrong" mesh list >/dev/null 2>&1
check "wrong token: exit 1" test $? -eq 1
"${S[@]}" health >"$tmp/health.txt"
check "health needs no token" grep -qx SERVING "$tmp/health.txt"
"$GEODEX" --server "127.0.0.1:$port" health >/dev/null 2>&1
check "plaintext to the TLS port fails" test $? -ne 0
kill -0 "$geodexd_pid"
check "the server survived all of it" test $? -eq 0

finish "secure cli"
