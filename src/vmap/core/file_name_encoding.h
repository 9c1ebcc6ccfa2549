#pragma once
// File names and paths in vmap's JSON files (map.json, sweep.json, `vmap match --json`).
//
// On Linux a file name is any sequence of bytes, while JSON text must be UTF-8. vmap therefore writes every
// file name and path in percent-encoded form: a byte that is not part of a valid UTF-8 sequence, and '%'
// itself, become "%XX" (two upper-case hex digits); everything else is kept as it is. So "caf\xE9.png"
// (Latin-1) is written "caf%E9.png", "100%.png" is written "100%25.png", and a valid UTF-8 name without '%'
// ("café.png") is written unchanged. Decoding turns every "%XX" back into its byte and keeps a '%' that is not
// followed by two hex digits, so the scheme is reversible: DecodeFileName(EncodeFileName(x)) == x for every x.

#include <string>
#include <string_view>

namespace vmap {

// Valid UTF-8 text (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF) for any bytes.
std::string EncodeFileName(std::string_view bytes);

// The bytes EncodeFileName was given.
std::string DecodeFileName(std::string_view text);

// Whether `bytes` is valid UTF-8 (RFC 3629).
bool IsValidUtf8(std::string_view bytes);

}  // namespace vmap
