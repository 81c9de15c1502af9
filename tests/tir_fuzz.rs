//! Robustness: thousands of byte strings derived from real files by seeded
//! random mutations (rand_chacha, so failures reproduce). The reader must
//! never panic; whatever it accepts must survive the writer (bit-exact
//! parameters and the same version on re-read).

use crate::tir_common;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tyrekit::tir::TyreParams;

const TOKENS: &[&[u8]] = &[
    b"$",
    b"!",
    b"'",
    b"[",
    b"]",
    b"=",
    b"{",
    b"}",
    b"(",
    b")",
    b"\r",
    b"\n",
    b"\t",
    b" ",
    b"\xff",
    b"\xc3",
    b"\xe2\x82",
    b"\0",
    b"1e999",
    b"-",
    b"NaN",
    b"''",
    b"1.0D-3",
    b"\nFITTYP = 61\n",
    b"\nFITTYP = 7\n",
    b"\n[UNITS]\nLENGTH = 'mm'\nFORCE='kN'\n",
    b"\n[UNITS]\nLENGTH = 'parsec'\n",
    b"\n[DEFLECTION_LOAD_CURVE]\n{pen fz}\n0 0\n1 2 3\n",
    b"\nPROPERTY_FILE_FORMAT = 'PAC2002'\n",
    b"\nFUNCTION_NAME = 'HTire::TYR501'\n",
    b"\n(COMMENTS)\n{comment_string}\n'x'\n",
    b"\nTYRESIDE = 'RIGHT'\n",
    b"\nLFZ0 = 2\n",
    b"\nPDY1 =\n",
    b"\nMASS = kg\n",
];

fn seeds() -> Vec<Vec<u8>> {
    let mut v: Vec<Vec<u8>> = tir_common::tir_files()
        .iter()
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    v.push(tyrekit::tir::BUILTIN_TIR.as_bytes().to_vec());
    v.push(b"[MODEL]\nFITTYP = 62\n[LATERAL_COEFFICIENTS]\nPDY1 = 1\n[SHAPE]\n1 0\n".to_vec());
    v
}

fn mutate(rng: &mut ChaCha8Rng, b: &mut Vec<u8>) {
    let n = rng.gen_range(1..=8);
    for _ in 0..n {
        let len = b.len();
        match rng.gen_range(0..6) {
            0 if len > 0 => {
                let i = rng.gen_range(0..len);
                b[i] = rng.gen();
            }
            1 => {
                let t = TOKENS[rng.gen_range(0..TOKENS.len())];
                let i = rng.gen_range(0..=len);
                b.splice(i..i, t.iter().copied());
            }
            2 if len > 0 => {
                let i = rng.gen_range(0..len);
                let j = (i + rng.gen_range(0..200)).min(len);
                b.drain(i..j);
            }
            3 if len > 0 => {
                let i = rng.gen_range(0..len);
                let j = (i + rng.gen_range(0..400)).min(len);
                let piece: Vec<u8> = b[i..j].to_vec();
                let k = rng.gen_range(0..=len);
                b.splice(k..k, piece);
            }
            4 if len > 0 => {
                let i = rng.gen_range(0..len);
                b.truncate(i);
            }
            _ => {
                // Random junk line.
                let i = rng.gen_range(0..=len);
                let junk: Vec<u8> = (0..rng.gen_range(0..40)).map(|_| rng.gen()).collect();
                b.splice(i..i, junk);
            }
        }
    }
}

#[test]
fn mutated_files_never_panic_and_what_is_accepted_round_trips() {
    let seeds = seeds();
    let seed = std::env::var("TIR_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x7172_2026u64);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut ok, mut refused) = (0usize, 0usize);
    // TIR_FUZZ_ITERS=100000 for a longer local run.
    let iters: usize = std::env::var("TIR_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4000);
    for iter in 0..iters {
        let mut b = seeds[rng.gen_range(0..seeds.len())].clone();
        mutate(&mut rng, &mut b);
        let r = std::panic::catch_unwind(|| TyreParams::from_bytes(&b, "fuzz.tir"));
        let r = match r {
            Ok(r) => r,
            Err(_) => {
                let dump = std::env::temp_dir().join(format!("tir_fuzz_{iter}.tir"));
                let _ = std::fs::write(&dump, &b);
                panic!(
                    "iteration {iter}: the reader panicked; input saved to {}",
                    dump.display()
                );
            }
        };
        match r {
            Ok(t) => {
                ok += 1;
                let text = t.to_tir_string();
                let back = TyreParams::from_tir_str(&text, "fuzz-back.tir").unwrap_or_else(|e| {
                    let dump = std::env::temp_dir().join(format!("tir_fuzz_{iter}.tir"));
                    let _ = std::fs::write(&dump, &b);
                    panic!("iteration {iter}: written file does not read back ({e}); input saved to {}", dump.display())
                });
                if back.version != t.version || back.side != t.side || back.defaulted != t.defaulted
                {
                    let dump = std::env::temp_dir().join(format!("tir_fuzz_{iter}.tir"));
                    let _ = std::fs::write(&dump, &b);
                    panic!(
                        "iteration {iter}: version {:?} -> {:?}, side {:?} -> {:?}, defaulted {} -> {}; input saved to {}",
                        t.version, back.version, t.side, back.side, t.defaulted.len(), back.defaulted.len(), dump.display()
                    );
                }
                for (k, (a, c)) in tyrekit::tir::KEYS
                    .iter()
                    .zip(t.p.as_slice().iter().zip(back.p.as_slice()))
                {
                    if a.to_bits() != c.to_bits() {
                        let dump = std::env::temp_dir().join(format!("tir_fuzz_{iter}.tir"));
                        let _ = std::fs::write(&dump, &b);
                        panic!(
                            "iteration {iter}: {} = {a} reads back as {c}; input saved to {}",
                            k.name,
                            dump.display()
                        );
                    }
                }
            }
            Err(e) => {
                refused += 1;
                // Errors are Tir errors that name the file.
                let msg = e.to_string();
                assert!(msg.starts_with("fuzz.tir:"), "iteration {iter}: {msg}");
            }
        }
    }
    eprintln!("fuzz: {ok} accepted, {refused} refused");
    assert!(
        ok > 1000,
        "mutations too destructive to test the writer: {ok} accepted"
    );
}

#[test]
fn random_bytes_never_panic() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    // Bytes drawn mostly from the characters that matter to the lexer.
    const ALPHABET: &[u8] = b"[]{}()=$!'\"\r\n\t .-+eEdD0123456789FITYPABCLMNOQRSUWXZ_\xff\xfe\x80";
    for iter in 0..1500 {
        let len = rng.gen_range(0..3000);
        let b: Vec<u8> = (0..len)
            .map(|_| {
                if rng.gen_bool(0.9) {
                    ALPHABET[rng.gen_range(0..ALPHABET.len())]
                } else {
                    rng.gen()
                }
            })
            .collect();
        let r = std::panic::catch_unwind(|| {
            TyreParams::from_bytes(&b, "random.tir").map(|t| t.to_tir_string())
        });
        if r.is_err() {
            let dump = std::env::temp_dir().join(format!("tir_random_{iter}.tir"));
            let _ = std::fs::write(&dump, &b);
            panic!(
                "iteration {iter}: panicked; input saved to {}",
                dump.display()
            );
        }
    }
}
