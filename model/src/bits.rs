//! Packing of stream items into flat bit vectors, LSB first, as `docs/numerics.md` lays out each
//! unit's fields. The RTL slices its flat `in_data_i` / `out_data_o` ports by the same lists.

/// Writes fields LSB first into 32-bit words.
#[derive(Debug, Default, Clone)]
pub struct BitWriter {
    words: Vec<u32>,
    len: u32,
}

impl BitWriter {
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends the low `width` bits of `value` (bits above `width` must be zero: a wider value is a
    /// caller bug that would corrupt the next field, so it is checked).
    pub fn put(&mut self, value: u64, width: u32) -> &mut Self {
        assert!(width <= 64, "field wider than 64 bits");
        assert!(
            width == 64 || value >> width == 0,
            "value {value:#x} does not fit in {width} bits"
        );
        let mut done = 0;
        while done < width {
            let pos = self.len + done;
            let word = (pos / 32) as usize;
            if word == self.words.len() {
                self.words.push(0);
            }
            let shift = pos % 32;
            let take = (32 - shift).min(width - done);
            let chunk = (value >> done) & ((1u64 << take) - 1);
            self.words[word] |= (chunk as u32) << shift;
            done += take;
        }
        self.len += width;
        self
    }

    pub fn put_bool(&mut self, value: bool) -> &mut Self {
        self.put(u64::from(value), 1)
    }

    /// Total bits written so far.
    pub fn len(&self) -> u32 {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The words, padded to `words_for(total_width)` so every item of a stream has the same size.
    pub fn finish(mut self, total_width: u32) -> Vec<u32> {
        assert_eq!(
            self.len, total_width,
            "packed width differs from the declared width"
        );
        self.words.resize(words_for(total_width), 0);
        self.words
    }

    /// The words of an item narrower than its stream's `total_width` bits (a stream whose kinds
    /// of item carry payloads of different widths, a configuration word with unused bits),
    /// zero-padded to that width.
    pub fn finish_padded(mut self, total_width: u32) -> Vec<u32> {
        assert!(
            self.len <= total_width,
            "packed width {} exceeds the declared width {total_width}",
            self.len
        );
        self.len = total_width;
        self.finish(total_width)
    }
}

/// Reads fields LSB first from 32-bit words.
#[derive(Debug, Clone)]
pub struct BitReader<'a> {
    words: &'a [u32],
    pos: u32,
}

impl<'a> BitReader<'a> {
    pub fn new(words: &'a [u32]) -> Self {
        Self { words, pos: 0 }
    }

    pub fn get(&mut self, width: u32) -> u64 {
        assert!(width <= 64, "field wider than 64 bits");
        let mut value = 0u64;
        let mut done = 0;
        while done < width {
            let pos = self.pos + done;
            let word = self.words.get((pos / 32) as usize).copied().unwrap_or(0);
            let shift = pos % 32;
            let take = (32 - shift).min(width - done);
            let chunk = (u64::from(word) >> shift) & ((1u64 << take) - 1);
            value |= chunk << done;
            done += take;
        }
        self.pos += width;
        value
    }

    pub fn get_bool(&mut self) -> bool {
        self.get(1) == 1
    }

    pub fn position(&self) -> u32 {
        self.pos
    }
}

/// 32-bit words needed for `width` bits (at least one, as Verilator stores a 0-bit port in one).
pub fn words_for(width: u32) -> usize {
    (width.max(1)).div_ceil(32) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_narrower_item_is_zero_padded_to_the_stream_width() {
        let mut w = BitWriter::new();
        w.put(0x3, 2);
        assert_eq!(w.clone().finish_padded(70), vec![3, 0, 0]);
        w.put(0x1, 1);
        assert_eq!(w.finish_padded(3), vec![7]);
    }

    #[test]
    fn round_trip_across_word_boundaries() {
        let fields = [
            (0x5u64, 3),
            (0xabcdef, 24),
            (0x1, 1),
            (0x1234_5678_9abc, 48),
            (0, 7),
        ];
        let total: u32 = fields.iter().map(|f| f.1).sum();
        let mut w = BitWriter::new();
        for (v, n) in fields {
            w.put(v, n);
        }
        let words = w.finish(total);
        assert_eq!(words.len(), words_for(total));
        let mut r = BitReader::new(&words);
        for (v, n) in fields {
            assert_eq!(r.get(n), v);
        }
    }

    #[test]
    #[should_panic(expected = "does not fit")]
    fn oversized_field_is_caught() {
        BitWriter::new().put(8, 3);
    }
}
