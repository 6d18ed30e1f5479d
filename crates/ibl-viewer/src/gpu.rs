//! The GPU the viewer draws with: one wgpu instance, adapter, device and queue, shared by the
//! headless path and the window (the window hands this same device to eframe, so both paths run
//! the same pipelines with the same features and limits).
//!
//! Backends come from `WGPU_BACKEND` when it is set (`vulkan`, `gl`, ...), otherwise every
//! backend this build has (Vulkan first; on a machine without a GPU, Mesa's lavapipe is a Vulkan
//! device of type CPU, and llvmpipe through EGL is the GL fallback). Optional features are taken
//! when the adapter has them: timestamp queries (per-pass GPU times). Required: 4x multisampling of
//! `Rgba16Float` and `Depth32Float`, which every Vulkan, Metal and DX12 device and lavapipe have.

use std::sync::{Arc, Mutex, PoisonError};

use crate::ViewerError;

/// Colour format of the HDR targets (linear radiance).
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Depth format of the main pass and of the shadow atlases.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Format of the tone-mapped picture (sRGB-encoded values in a UNORM texture, what egui shows).
pub const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Formats of the scene's geometry pass (`frame_targets.rs`), 4x multisampled: view depth and
/// surface id (one 32-bit float each), the octahedral shading and geometric normals
/// (`Rgba16Float`, about 1e-3 rad), 16 bytes a sample in all. Vulkan devices multisample all
/// three; [`GpuContext::open`] refuses an adapter that cannot.
pub const GBUFFER_FORMATS: [wgpu::TextureFormat; 3] = [
    wgpu::TextureFormat::R32Float,
    wgpu::TextureFormat::R32Float,
    wgpu::TextureFormat::Rgba16Float,
];

/// What the adapter is, for status lines and reports.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct AdapterSummary {
    /// Device name, e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`.
    pub name: String,
    /// Backend, e.g. `vulkan`.
    pub backend: String,
    /// Device type: `cpu` (software), `discrete`, `integrated`, `virtual`, `other`.
    pub device_type: String,
    /// Driver and its version.
    pub driver: String,
}

impl AdapterSummary {
    fn of(info: &wgpu::AdapterInfo) -> AdapterSummary {
        let device_type = match info.device_type {
            wgpu::DeviceType::Cpu => "cpu",
            wgpu::DeviceType::DiscreteGpu => "discrete",
            wgpu::DeviceType::IntegratedGpu => "integrated",
            wgpu::DeviceType::VirtualGpu => "virtual",
            wgpu::DeviceType::Other => "other",
        };
        AdapterSummary {
            name: info.name.clone(),
            backend: info.backend.to_str().to_string(),
            device_type: device_type.to_string(),
            driver: format!("{} {}", info.driver, info.driver_info)
                .trim()
                .to_string(),
        }
    }

    /// One line: `llvmpipe (LLVM 15.0.6, 256 bits), vulkan, cpu`.
    pub fn line(&self) -> String {
        format!("{}, {}, {}", self.name, self.backend, self.device_type)
    }
}

/// An open GPU.
#[derive(Clone, Debug)]
pub struct GpuContext {
    /// The instance the adapter came from (the window makes its surface from it).
    pub instance: wgpu::Instance,
    /// The adapter.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter is.
    pub summary: AdapterSummary,
    /// Whether GPU timestamps can be written at pass boundaries.
    pub timestamps: bool,
    /// Errors the device reported outside an error scope (validation, out of memory), oldest
    /// first: collected here instead of wgpu's default handler, which panics.
    pub errors: Arc<Mutex<Vec<String>>>,
}

/// The features the viewer asks for on `adapter`: timestamps when available, nothing required.
pub fn wanted_features(adapter: &wgpu::Adapter) -> wgpu::Features {
    adapter.features() & wgpu::Features::TIMESTAMP_QUERY
}

/// The device descriptor the viewer uses on `adapter` (also given to eframe for the window).
pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    wgpu::DeviceDescriptor {
        label: Some("ibl-viewer"),
        required_features: wanted_features(adapter),
        // Everything the adapter offers: large shadow atlases need its largest 2-D texture.
        required_limits: adapter.limits(),
        experimental_features: wgpu::ExperimentalFeatures::disabled(),
        memory_hints: wgpu::MemoryHints::Performance,
        trace: wgpu::Trace::Off,
    }
}

/// Whether `adapter` can render what the viewer renders (4x MSAA of the HDR, depth and geometry
/// formats). Mesa's OpenGL adapter (llvmpipe, what wgpu finds where Vulkan is not installed)
/// cannot multisample `R32Float`: refused here with that reason, instead of a validation error
/// at the first frame.
fn check_adapter(adapter: &wgpu::Adapter) -> Result<(), String> {
    for format in [HDR_FORMAT, DEPTH_FORMAT]
        .into_iter()
        .chain(GBUFFER_FORMATS)
    {
        let flags = adapter.get_texture_format_features(format).flags;
        if !flags.sample_count_supported(4) {
            return Err(format!("{format:?} cannot be multisampled 4x"));
        }
    }
    Ok(())
}

impl GpuContext {
    /// Opens the best adapter for offscreen rendering (`WGPU_BACKEND` honoured).
    pub fn headless() -> Result<GpuContext, ViewerError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter =
            pollster::block_on(
                instance.request_adapter(&wgpu::RequestAdapterOptions {
                    power_preference: wgpu::PowerPreference::from_env()
                        .unwrap_or(wgpu::PowerPreference::HighPerformance),
                    force_fallback_adapter: false,
                    compatible_surface: None,
                    apply_limit_buckets: false,
                }),
            )
            .map_err(|e| ViewerError::NoAdapter(e.to_string()))?;
        Self::open(instance, adapter)
    }

    /// Opens `adapter` (from `instance`) with [`device_descriptor`].
    pub fn open(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
    ) -> Result<GpuContext, ViewerError> {
        let info = adapter.get_info();
        check_adapter(&adapter).map_err(|why| {
            ViewerError::NoAdapter(format!("{} cannot be used: {why}", info.name))
        })?;
        let descriptor = device_descriptor(&adapter);
        let timestamps = descriptor
            .required_features
            .contains(wgpu::Features::TIMESTAMP_QUERY);
        let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))
            .map_err(|e| ViewerError::Device(format!("{}: {e}", info.name)))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = Arc::clone(&errors);
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock()
                .unwrap_or_else(PoisonError::into_inner)
                .push(e.to_string());
        }));
        Ok(GpuContext {
            errors,
            instance,
            summary: AdapterSummary::of(&info),
            adapter,
            device,
            queue,
            timestamps,
        })
    }

    /// The errors reported since the last call, as one [`ViewerError::Gpu`] (`Ok` when none).
    pub fn take_errors(&self) -> Result<(), ViewerError> {
        let errors =
            std::mem::take(&mut *self.errors.lock().unwrap_or_else(PoisonError::into_inner));
        match errors.first() {
            None => Ok(()),
            Some(first) if errors.len() == 1 => Err(ViewerError::Gpu(first.clone())),
            Some(first) => Err(ViewerError::Gpu(format!(
                "{first} (and {} more errors)",
                errors.len() - 1
            ))),
        }
    }

    /// Largest side of a 2-D texture on this device, texels.
    pub fn max_texture_side(&self) -> u32 {
        self.device.limits().max_texture_dimension_2d
    }
}
