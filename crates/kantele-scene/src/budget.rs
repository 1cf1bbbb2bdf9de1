//! The memory budget of one load: every allocation whose size the file controls is charged here
//! first, by arithmetic on the declared sizes, so a hostile file is refused before it allocates.

/// Bytes a load may still allocate for what the file controls.
#[derive(Debug)]
pub(crate) struct Budget {
    limit: u64,
    used: u64,
}

impl Budget {
    /// A budget of `limit` bytes.
    pub(crate) fn new(limit: u64) -> Self {
        Self { limit, used: 0 }
    }

    /// Charges `count × each` bytes for `what`; an error (naming `what`, the size and the
    /// budget) when that does not fit. Overflowing products never fit.
    pub(crate) fn charge(&mut self, count: u64, each: u64, what: &str) -> Result<(), String> {
        let bytes = count.checked_mul(each);
        match bytes.and_then(|b| self.used.checked_add(b)) {
            Some(total) if total <= self.limit => {
                self.used = total;
                Ok(())
            }
            _ => Err(format!(
                "{what} would need {} but the load's memory budget is {} ({} already used; raise it with --max-memory)",
                human(bytes),
                human(Some(self.limit)),
                human(Some(self.used)),
            )),
        }
    }
}

/// Bytes in a form people read (`1.5 GiB`); `None` is "more than 16 EiB".
fn human(bytes: Option<u64>) -> String {
    let Some(bytes) = bytes else {
        return "more than 16 EiB".to_string();
    };
    let units = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < units.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{value:.1} {}", units[unit])
    }
}

/// A `Vec` with room for `n` elements, or an error when the allocator refuses (sizes come from
/// input that the budget already accepted; this catches what the budget cannot see).
pub(crate) fn vec_with_capacity<T>(n: usize, what: &str) -> Result<Vec<T>, String> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| format!("{what}: cannot allocate {n} elements"))?;
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn charges_until_the_limit_and_refuses_overflow() {
        let mut b = Budget::new(1000);
        assert!(b.charge(10, 50, "a").is_ok());
        assert!(b.charge(50, 10, "b").is_ok());
        let e = b.charge(1, 1, "c").unwrap_err();
        assert!(e.contains("c would need 1 bytes"), "{e}");
        assert!(b
            .charge(u64::MAX, 2, "huge")
            .unwrap_err()
            .contains("16 EiB"));
        assert_eq!(human(Some(3 << 30)), "3.0 GiB");
    }
}
