//! The types of the generated register maps (`crate::regs`): a register's bus access, the register
//! itself and a field of it. Hand-written here once; `cube5-gen regs` generates only the maps that
//! use them (docs/adding-a-unit.md, "Registers and shared constants").

/// Who may access a register on the bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// Read and write.
    Rw,
    /// Read only.
    Ro,
    /// Write only.
    Wo,
    /// Read; writing 1 clears that bit.
    W1c,
}

/// One register: name, word offset, access, reset value (`None`: reset leaves it as it is).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Register {
    pub name: &'static str,
    pub offset: u32,
    pub access: Access,
    pub reset: Option<u64>,
}

impl Register {
    pub const fn new(name: &'static str, offset: u32, access: Access, reset: Option<u64>) -> Self {
        Self {
            name,
            offset,
            access,
            reset,
        }
    }

    /// Byte address on a bus of `word_bytes`-byte registers whose offset 0 is at `base`.
    pub const fn byte_addr(&self, base: u64, word_bytes: u64) -> u64 {
        base + self.offset as u64 * word_bytes
    }
}

/// A bit field of a register: `width` bits (1..=64) from bit `lsb`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    pub lsb: u32,
    pub width: u32,
}

impl Field {
    pub const fn new(lsb: u32, width: u32) -> Self {
        Self { lsb, width }
    }

    /// The field's bits in the register word.
    pub const fn mask(self) -> u64 {
        (u64::MAX >> (64 - self.width)) << self.lsb
    }

    /// The field's value in `word`.
    pub const fn get(self, word: u64) -> u64 {
        (word & self.mask()) >> self.lsb
    }

    /// `word` with the field set to `value` (bits of `value` above the field are dropped).
    pub const fn set(self, word: u64, value: u64) -> u64 {
        (word & !self.mask()) | ((value << self.lsb) & self.mask())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_get_set() {
        let f = Field::new(1, 4);
        assert_eq!(f.mask(), 0x1e);
        assert_eq!(f.set(0x21, 0xff), 0x3f);
        assert_eq!(f.get(0x3f), 0xf);
        assert_eq!(Field::new(0, 64).mask(), u64::MAX);
    }
}
