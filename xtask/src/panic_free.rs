//! A panic-free tick, checked on the linked image: nothing reachable by
//! direct calls from the QEMU twin's `tick_path` (sensor read, estimator,
//! twin) and `telemetry_path` (defmt packing of the record) is a panic
//! entry point (`core::panicking::*`, slice and `str` index failures,
//! `unwrap`/`expect` failures, assertion failures).
//!
//! The call graph comes from the image itself (after LTO: what the
//! controller runs), decoded from the Thumb-2 code of every function
//! symbol: `BL`, `B.W` and `B<c>.W` (32-bit), `B` and `B<c>` (16-bit) to a
//! target outside the function are edges; literal pools (`$d` mapping
//! symbols) are skipped. Indirect calls (`BLX rN`, function pointers) are
//! not followed: the tick path has none but defmt's logger trait, whose
//! functions (`_defmt_*`) are reached directly too.

use object::{Object, ObjectSection, ObjectSymbol, SymbolKind};
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::Path;

/// Substrings of (mangled) symbol names that mark a panic entry point.
const PANICS: [&str; 7] = [
    "panic",
    "slice_index",
    "slice_start_index",
    "slice_end_index",
    "str_index",
    "unwrap_failed",
    "expect_failed",
];

/// A function of the image: `[start, end)` and its (mangled) name.
struct Function {
    start: u64,
    end: u64,
    name: String,
}

/// Direct-call targets of the Thumb-2 instruction whose halfwords are `hw1`
/// (and `hw2` for a 32-bit one) at address `pc`.
fn branch_target(pc: u64, hw1: u16, hw2: Option<u16>) -> Option<u64> {
    let sign_extend = |v: u32, bits: u32| -> i64 { ((v << (32 - bits)) as i32 >> (32 - bits)) as i64 };
    let at = |off: i64| Some((pc as i64 + 4 + off) as u64);
    match hw2 {
        Some(hw2) => {
            if hw1 >> 11 != 0b11110 || hw2 & 0x8000 == 0 {
                return None;
            }
            let (h1, h2) = (u32::from(hw1), u32::from(hw2));
            let s = (h1 >> 10) & 1;
            let (j1, j2) = ((h2 >> 13) & 1, (h2 >> 11) & 1);
            match hw2 & 0xD000 {
                // BL (T1) and B.W (T4).
                0xD000 | 0x9000 => {
                    let (i1, i2) = (!(j1 ^ s) & 1, !(j2 ^ s) & 1);
                    let imm = (s << 24) | (i1 << 23) | (i2 << 22) | ((h1 & 0x3FF) << 12) | ((h2 & 0x7FF) << 1);
                    at(sign_extend(imm, 25))
                }
                // B<c>.W (T3); a condition of 111x is another instruction.
                0x8000 if (h1 >> 7) & 0b111 != 0b111 => {
                    let imm = (s << 20) | (j2 << 19) | (j1 << 18) | ((h1 & 0x3F) << 12) | ((h2 & 0x7FF) << 1);
                    at(sign_extend(imm, 21))
                }
                _ => None,
            }
        }
        None => {
            let h = u32::from(hw1);
            if hw1 >> 11 == 0b11100 {
                // B (T2).
                at(sign_extend((h & 0x7FF) << 1, 12))
            } else if hw1 >> 12 == 0b1101 && (h >> 8) & 0xF < 0b1110 {
                // B<c> (T1).
                at(sign_extend((h & 0xFF) << 1, 9))
            } else {
                None
            }
        }
    }
}

/// The functions of `.text`, and for each its direct callees (by index).
fn call_graph(data: &[u8]) -> Result<(Vec<Function>, Vec<BTreeSet<usize>>), String> {
    let file = object::File::parse(data).map_err(|e| e.to_string())?;
    let text = file.section_by_name(".text").ok_or("no .text")?;
    let (base, code) = (text.address(), text.data().map_err(|e| e.to_string())?);
    let mut functions: Vec<Function> = file
        .symbols()
        .filter(|s| s.kind() == SymbolKind::Text && s.size() > 0)
        .filter_map(|s| {
            let start = s.address() & !1;
            let name = s.name().ok()?.to_string();
            (start >= base && start < base + code.len() as u64).then(|| Function {
                start,
                end: start + s.size(),
                name,
            })
        })
        .collect();
    functions.sort_by_key(|f| f.start);
    functions.dedup_by_key(|f| f.start);
    // Mapping symbols: `$d` starts data (a literal pool), `$t` code again.
    let marks: BTreeMap<u64, bool> = file
        .symbols()
        .filter_map(|s| {
            let name = s.name().ok()?;
            let data = name == "$d" || name.starts_with("$d.");
            let thumb = name == "$t" || name.starts_with("$t.");
            (data || thumb).then_some((s.address() & !1, data))
        })
        .collect();
    let index_of = |addr: u64| -> Option<usize> {
        let i = functions.partition_point(|f| f.start <= addr).checked_sub(1)?;
        (addr < functions[i].end).then_some(i)
    };
    let halfword = |addr: u64| -> Option<u16> {
        let o = usize::try_from(addr.checked_sub(base)?).ok()?;
        Some(u16::from_le_bytes([*code.get(o)?, *code.get(o + 1)?]))
    };
    let mut edges = vec![BTreeSet::new(); functions.len()];
    for (i, f) in functions.iter().enumerate() {
        let mut pc = f.start;
        while pc + 2 <= f.end {
            if let Some((_, true)) = marks.range(..=pc).next_back() {
                // Inside a literal pool: on to the next code mark.
                match marks.range(pc + 1..).find(|(_, data)| !**data) {
                    Some((&next, _)) if next < f.end => {
                        pc = next;
                        continue;
                    }
                    _ => break,
                }
            }
            let Some(hw1) = halfword(pc) else { break };
            let wide = matches!(hw1 >> 11, 0b11101..=0b11111);
            let hw2 = if wide { halfword(pc + 2) } else { None };
            if let Some(t) = branch_target(pc, hw1, hw2)
                && let Some(j) = index_of(t)
                && j != i
            {
                edges[i].insert(j);
            }
            pc += if wide { 4 } else { 2 };
        }
    }
    Ok((functions, edges))
}

/// Checks that no panic entry point is reachable from the functions whose
/// names contain one of `roots`, not looking into the functions named in
/// `opaque` (a dependency's code the check accepts, each for a stated
/// reason). Returns a one-line summary; the error names a call chain to
/// the panic.
pub fn check(elf: &Path, roots: &[&str], opaque: &[&str]) -> Result<String, String> {
    let data = std::fs::read(elf).map_err(|e| format!("{}: {e}", elf.display()))?;
    let (functions, edges) = call_graph(&data).map_err(|e| format!("{}: {e}", elf.display()))?;
    let mut summary = Vec::new();
    for root in roots {
        let start = functions
            .iter()
            .position(|f| f.name.contains(root))
            .ok_or_else(|| format!("{}: no function named like {root} (inlined?)", elf.display()))?;
        let mut parent: BTreeMap<usize, usize> = BTreeMap::new();
        let mut queue = VecDeque::from([start]);
        let mut seen = BTreeSet::from([start]);
        while let Some(f) = queue.pop_front() {
            if PANICS.iter().any(|p| functions[f].name.contains(p)) {
                let mut chain = vec![functions[f].name.clone()];
                let mut at = f;
                while let Some(&p) = parent.get(&at) {
                    chain.push(functions[p].name.clone());
                    at = p;
                }
                return Err(format!(
                    "{}: a panic is reachable from {root}: {}",
                    elf.display(),
                    chain.join(" <- ")
                ));
            }
            if f != start && opaque.iter().any(|o| functions[f].name.contains(o)) {
                continue;
            }
            for &g in &edges[f] {
                if seen.insert(g) {
                    parent.insert(g, f);
                    queue.push_back(g);
                }
            }
        }
        summary.push(format!("{root}: {} functions reachable, no panic", seen.len()));
    }
    if !opaque.is_empty() {
        summary.push(format!("not looked into: {}", opaque.join(", ")));
    }
    Ok(summary.join("; "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thumb_branches_decode_to_their_targets() {
        // bl 0x800c618 at 0x800669e (from the twin image's disassembly).
        assert_eq!(branch_target(0x800669e, 0xf005, Some(0xffbb)), Some(0x800c618));
        // b.w backwards: f7ff bffe is `b.w .` (a branch to itself).
        assert_eq!(branch_target(0x1000, 0xf7ff, Some(0xbffe)), Some(0x1000));
        // 16-bit b . (e7fe) and beq . (d0fe).
        assert_eq!(branch_target(0x2000, 0xe7fe, None), Some(0x2000));
        assert_eq!(branch_target(0x2000, 0xd0fe, None), Some(0x2000));
        // Not branches: a 16-bit add, svc (df00), udf (de00).
        assert_eq!(branch_target(0x2000, 0x1840, None), None);
        assert_eq!(branch_target(0x2000, 0xdf00, None), None);
        assert_eq!(branch_target(0x2000, 0xde00, None), None);
    }
}
