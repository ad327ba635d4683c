//! Flash and static RAM of a firmware image, from its ELF sections:
//! `.vector_table`, `.text`, `.rodata`, `.data` in flash; `.data`, `.bss`,
//! `.uninit` in RAM.

use object::{Object, ObjectSection};
use std::path::Path;

/// Flash and static RAM of one image [bytes].
#[derive(Debug, Clone)]
pub struct Footprint {
    /// The image as the budget table names it (`board image`).
    pub label: &'static str,
    pub flash: u64,
    pub ram: u64,
}

/// Flash and static RAM of an ELF image.
pub fn footprint(label: &'static str, elf: &Path) -> Result<Footprint, String> {
    let data = std::fs::read(elf).map_err(|e| format!("{}: {e}", elf.display()))?;
    let file = object::File::parse(&*data).map_err(|e| format!("{}: {e}", elf.display()))?;
    let (mut flash, mut ram) = (0, 0);
    for s in file.sections() {
        let name = s.name().unwrap_or_default();
        let size = s.size();
        match name {
            ".vector_table" | ".text" | ".rodata" => flash += size,
            ".data" => {
                flash += size; // initial values, copied at reset
                ram += size;
            }
            ".bss" | ".uninit" => ram += size,
            _ => {}
        }
    }
    Ok(Footprint { label, flash, ram })
}
