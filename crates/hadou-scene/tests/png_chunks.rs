//! A PNG's ancillary chunks cost nothing to decode: a 7 MB iCCP (or zTXt/iTXt) chunk that
//! inflates to 1 GiB is skipped unread. Its own test binary, so the process's peak resident size
//! measures this one decode.

mod common;

use common::chunk;
use hadou_scene::{decode_texture, encode_png};

/// Bits written least significant first, as deflate packs them.
#[derive(Default)]
struct Bits {
    out: Vec<u8>,
    acc: u64,
    n: u32,
}

impl Bits {
    fn push(&mut self, value: u64, count: u32) {
        self.acc |= value << self.n;
        self.n += count;
        while self.n >= 8 {
            self.out.push(self.acc as u8);
            self.acc >>= 8;
            self.n -= 8;
        }
    }

    /// A Huffman code: its bits go most significant first.
    fn code(&mut self, code: u64, len: u32) {
        for i in (0..len).rev() {
            self.push(code >> i & 1, 1);
        }
    }

    fn finish(mut self) -> Vec<u8> {
        if self.n > 0 {
            self.out.push(self.acc as u8);
        }
        self.out
    }
}

/// A zlib stream inflating to `1 + 258·repeats` zero bytes: one fixed-Huffman block of a literal
/// 0 and `repeats` copies of <length 258, distance 1> (13 bits each).
fn zlib_bomb(repeats: usize) -> Vec<u8> {
    let mut b = Bits::default();
    b.push(1, 1); // BFINAL
    b.push(1, 2); // BTYPE = 01, fixed codes
    b.code(0x30, 8); // literal 0
    for _ in 0..repeats {
        b.code(0b1100_0101, 8); // length symbol 285: 258
        b.code(0, 5); // distance code 0: 1
    }
    b.code(0, 7); // end of block
    let n = 1 + 258 * repeats as u64;
    let mut out = vec![0x78, 0x01];
    out.extend(b.finish());
    out.extend_from_slice(&((n % 65521) << 16 | 1).to_be_bytes()[4..]);
    out
}

/// The peak resident set of this process, in bytes (Linux `VmHWM`).
fn peak_resident() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kb = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .unwrap_or(0);
    kb * 1024
}

#[test]
fn png_icc_and_text_chunks_that_inflate_to_a_gibibyte_are_skipped() {
    let texels: Vec<[u8; 4]> = (0..16).map(|i| [i * 16, 255 - i * 16, 7, 255]).collect();
    let plain = encode_png(4, 4, &texels);
    // 1 GiB of zeros once inflated (4 161 790 copies of 258 bytes), about 6.8 MB compressed.
    let bomb = zlib_bomb((1 << 30) / 258);
    let mut iccp = b"icc\0\0".to_vec();
    iccp.extend_from_slice(&bomb);
    let mut ztxt = b"Comment\0\0".to_vec();
    ztxt.extend_from_slice(&bomb);
    let mut itxt = b"Comment\0\x01\0\0\0".to_vec();
    itxt.extend_from_slice(&bomb);
    // Signature and IHDR (8 + 25 bytes), then the ancillary chunks, then the rest (IDAT, IEND).
    let mut png = plain[..33].to_vec();
    png.extend(chunk(b"iCCP", &iccp));
    png.extend(chunk(b"zTXt", &ztxt));
    png.extend(chunk(b"iTXt", &itxt));
    png.extend_from_slice(&plain[33..]);
    drop((iccp, ztxt, itxt, bomb));

    let before = peak_resident();
    let t = decode_texture(&png, "bomb.png", &mut Vec::new()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((t.width, t.height), (4, 4));
    assert_eq!(t.texels, texels);
    let after = peak_resident();
    if cfg!(target_os = "linux") {
        // The file itself is about 21 MB; inflating one chunk would take hundreds of MB more.
        assert!(after < before.max(64 << 20) + (64 << 20), "peak resident {before} → {after} bytes");
    }
}
