//! Geometric primitives and their ray-intersection and sampling kernels.

pub mod bilinear;
pub mod bounds;
pub mod disk;
pub mod ray;
pub mod sample;
pub mod sphere;
pub mod triangle;

pub use bilinear::{BilinearHit, BilinearPatch};
pub use bounds::Aabb;
pub use disk::{Disk, DiskHit};
pub use ray::{Ray, SHADOW_EPSILON, SurfacePoint};
pub use sample::{AreaSample, ShapeError, SolidAngleSample, area_pdf_to_solid_angle};
pub use sphere::{Sphere, SphereHit};
pub use triangle::{
    TriangleHit, WatertightRay, intersect_triangle, sample_triangle, triangle_area,
};
