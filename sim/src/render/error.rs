//! Why rendering is not possible.

/// Why rendering is not possible.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No GPU adapter (hardware or software driver) was found.
    #[error(
        "no GPU adapter found ({0}); on Debian/Ubuntu install Mesa's software Vulkan driver with \
         `sudo apt-get install mesa-vulkan-drivers libvulkan1`, or use --renderer cpu"
    )]
    NoAdapter(String),
    /// The device failed.
    #[error("GPU device error: {0}")]
    Device(String),
    /// The batch a frame was traced in failed (shared by every frame of the batch).
    #[error("GPU device error: {0}")]
    Batch(std::sync::Arc<RenderError>),
    /// The frame asked for cannot be made.
    #[error("cannot render: {0}")]
    Invalid(String),
}
