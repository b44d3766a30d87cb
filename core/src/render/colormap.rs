//! Perceptual colour maps for heatmaps, from the `colorous` crate (viridis and inferno: van der
//! Walt & Smith's matplotlib maps; turbo: Mikhailov 2019; the diverging red–blue: ColorBrewer's RdBu).

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum ColorMap {
    #[default]
    Viridis,
    Inferno,
    Magma,
    Turbo,
    /// Blue through white to red (colorous's red–blue, reversed): for differences, centred on 0.5.
    Diverging,
}

impl ColorMap {
    fn gradient(self) -> colorous::Gradient {
        match self {
            ColorMap::Viridis => colorous::VIRIDIS,
            ColorMap::Inferno => colorous::INFERNO,
            ColorMap::Magma => colorous::MAGMA,
            ColorMap::Turbo => colorous::TURBO,
            ColorMap::Diverging => colorous::RED_BLUE,
        }
    }

    /// Colour of `x` in [0, 1] (clamped; NaN maps to 0).
    #[inline]
    pub fn map(self, x: f32) -> [u8; 3] {
        let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
        // Red–blue runs from red at 0 to blue at 1; a difference's negative end (less work) is blue.
        let x = if self == ColorMap::Diverging { 1.0 - x } else { x };
        let c = self.gradient().eval_continuous(x as f64);
        [c.r, c.g, c.b]
    }
}
