//! Perceptual colour maps for heatmaps, from the `colorous` crate (viridis and inferno: van der
//! Walt & Smith's matplotlib maps; turbo: Mikhailov 2019).

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum ColorMap {
    #[default]
    Viridis,
    Inferno,
    Magma,
    Turbo,
}

impl ColorMap {
    fn gradient(self) -> colorous::Gradient {
        match self {
            ColorMap::Viridis => colorous::VIRIDIS,
            ColorMap::Inferno => colorous::INFERNO,
            ColorMap::Magma => colorous::MAGMA,
            ColorMap::Turbo => colorous::TURBO,
        }
    }

    /// Colour of `x` in [0, 1] (clamped; NaN maps to 0).
    #[inline]
    pub fn map(self, x: f32) -> [u8; 3] {
        let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
        let c = self.gradient().eval_continuous(x as f64);
        [c.r, c.g, c.b]
    }
}
