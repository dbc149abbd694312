//! White-box tests of the lighting technique against its CPU twins, under validation.
//! (Moved from `tests/` in issue 26: integration tests use only the front door.)

mod atmosphere;
mod cie;
mod distant;
mod figures;
mod reference;
mod sh_bands;
mod sh_bands_figure;
mod shadows;
mod sky_cache;
mod sky_hemisphere;
mod sky_light;
mod soft_shadows;
mod twins;
mod visibility_sh;
