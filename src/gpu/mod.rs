//! The GPU context a world runs on ([`Gpu`]: instance, adapter, device,
//! queue; one may serve several worlds and renderers), and why none could
//! be had ([`GpuError`]). The structs shared with WGSL and the shader
//! assembly live here too, for the crate itself and its tests.

// For the crate's own tests: the WGSL sources, the GPU's status record and
// the records shared with WGSL, checked against the shaders.
#[doc(hidden)]
pub mod shaders;
#[doc(hidden)]
pub mod status;
mod subnormals;
#[doc(hidden)]
pub mod types;

use std::collections::HashMap;
use std::fmt;

/// Why no GPU could be had.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("no GPU adapter found (on a machine without a GPU install a software Vulkan driver: `apt-get install mesa-vulkan-drivers`){0}")]
    NoAdapter(String),
    #[error("WGPU_ADAPTER_NAME={0:?} matches no adapter; found: {1}")]
    AdapterNameMismatch(String, String),
    /// An adapter-choosing environment variable (`WGPU_BACKEND`,
    /// `WGPU_POWER_PREF`) holds a value wgpu does not know: (variable, value,
    /// the values it takes).
    #[error("{0}={1:?} is not valid; it takes {2}")]
    BadEnv(&'static str, String, String),
    #[error("could not open the GPU device: {0}")]
    Device(String),
    #[error("GPU error: {0}")]
    Runtime(String),
    /// The device was lost (destroyed, driver reset, out of memory): every
    /// later call on it fails with this too.
    #[error("GPU device lost: {0}")]
    Lost(String),
    /// Submitted work did not finish within `WAIT_LIMIT`.
    #[error("GPU did not finish the submitted work within {0} s (hung or lost device)")]
    Timeout(u64),
}

/// The longest `Gpu::wait` waits for submitted work before giving up with
/// `GpuError::Timeout`. Generous: one submission is at most a batch of
/// steps, which on a software adapter with a huge scene takes seconds.
pub(crate) const WAIT_LIMIT: std::time::Duration = std::time::Duration::from_secs(300);

/// `Gpu::wait` polls in slices of this length, checking for a lost device
/// between them.
const WAIT_SLICE: std::time::Duration = std::time::Duration::from_secs(1);

/// An adapter, its device and queue.
pub struct Gpu {
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    /// The limits the device was opened with (the adapter's own, raised from
    /// wgpu's defaults so large scenes fit).
    pub limits: wgpu::Limits,
    /// The first error the device reported outside an error scope; wgpu's
    /// default would panic, this turns it into an `Err` at the next wait.
    errors: std::sync::Arc<std::sync::Mutex<Option<String>>>,
    /// Why the device was lost, once wgpu has said so (it calls the
    /// device-lost callback while polling).
    lost: std::sync::Arc<std::sync::Mutex<Option<String>>>,
    /// Held while polling and while submitting: wgpu-core 30.0 can panic
    /// when one thread waits on a device while another polls or submits to
    /// it (an assertion in `Device::maintain` races with a submission not yet
    /// tracked; fixed upstream in gfx-rs/wgpu#9958). Threads that share a
    /// `Gpu` (the tests do) take turns.
    polling: std::sync::Mutex<()>,
    /// Which `Gpu` of this process it is: wgpu's devices of two instances
    /// may compare equal (wgpu-core's ids are per instance).
    id: u64,
    /// Every compute kernel and bind group layout made so far, kept for the
    /// device's life: a second world, or an edit, compiles nothing.
    kernels: std::sync::Mutex<Kernels>,
}

/// The compiled compute pipelines of a device and the bind group layouts
/// they were made for (`Gpu::compute_pipelines`, `Gpu::bind_group_layout`).
#[derive(Default)]
struct Kernels {
    /// By their entries; the label is the first maker's.
    layouts: HashMap<Vec<wgpu::BindGroupLayoutEntry>, wgpu::BindGroupLayout>,
    pipelines: HashMap<KernelKey, wgpu::ComputePipeline>,
}

/// All that a compute pipeline is made from: the same key, the same kernel.
#[derive(PartialEq, Eq, Hash)]
struct KernelKey {
    source: String,
    entry: String,
    /// The bind group layouts (by identity: the cached ones are the same
    /// handles each time), or None for the shader's own.
    groups: Option<Vec<wgpu::BindGroupLayout>>,
    /// Override constants, by name and the bits of their value.
    constants: Vec<(String, u64)>,
}

impl fmt::Debug for Gpu {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Gpu").field("info", &self.info).finish()
    }
}

impl Gpu {
    /// Compute pipelines for the entry points `entries` of one WGSL module:
    /// the one way every compute kernel here is built (the step's passes,
    /// the input kernels, the bench's copy kernel). `bind_groups`: the
    /// layouts of its bind groups, or None to take them from the shader
    /// (`get_bind_group_layout`); `constants`: override constants. Each is
    /// compiled once per device and kept (the same source, entry point,
    /// layouts and constants give the same pipeline): compiling the step's
    /// passes takes a fifth of a second on a software adapter.
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn compute_pipelines(
        &self,
        label: &str,
        source: &str,
        entries: &[&str],
        bind_groups: Option<&[&wgpu::BindGroupLayout]>,
        constants: &[(&str, f64)],
    ) -> Vec<wgpu::ComputePipeline> {
        let key = |entry: &str| KernelKey {
            source: source.to_string(),
            entry: entry.to_string(),
            groups: bind_groups.map(|groups| groups.iter().map(|&g| g.clone()).collect()),
            constants: constants.iter().map(|&(name, value)| (name.to_string(), value.to_bits())).collect(),
        };
        let keys: Vec<KernelKey> = entries.iter().map(|e| key(e)).collect();
        let cached: Vec<Option<wgpu::ComputePipeline>> = {
            let kernels = self.kernels.lock().unwrap_or_else(|e| e.into_inner());
            keys.iter().map(|k| kernels.pipelines.get(k).cloned()).collect()
        };
        if cached.iter().all(Option::is_some) {
            return cached.into_iter().flatten().collect();
        }
        // compiled outside the lock: other threads' kernels need not wait
        let made = self.compile_pipelines(label, source, entries, bind_groups, constants);
        let mut kernels = self.kernels.lock().unwrap_or_else(|e| e.into_inner());
        // where another thread compiled one meanwhile, its pipeline is kept
        keys.into_iter().zip(made).map(|(k, p)| kernels.pipelines.entry(k).or_insert(p).clone()).collect()
    }

    fn compile_pipelines(
        &self,
        label: &str,
        source: &str,
        entries: &[&str],
        bind_groups: Option<&[&wgpu::BindGroupLayout]>,
        constants: &[(&str, f64)],
    ) -> Vec<wgpu::ComputePipeline> {
        // Without wgpu's loop bounding, whose per-loop counter keeps LLVM
        // from unrolling fixed loops (docs/lavapipe.md); every loop here ends
        // (`shaders::every_loop_counts_to_a_bound`). Bounds checks stay.
        let checks = wgpu::ShaderRuntimeChecks { force_loop_bounding: false, ..wgpu::ShaderRuntimeChecks::checked() };
        let descriptor = wgpu::ShaderModuleDescriptor { label: Some(label), source: wgpu::ShaderSource::Wgsl(source.into()) };
        // SAFETY: wgpu asks that no loop of a module made without loop
        // bounding run forever; see above.
        let module = unsafe { self.device.create_shader_module_trusted(descriptor, checks) };
        let layout = bind_groups.map(|groups| {
            let groups: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(|g| Some(*g)).collect();
            self.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &groups,
                immediate_size: 0,
            })
        });
        entries
            .iter()
            .map(|entry| {
                self.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: layout.as_ref(),
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
                    cache: None,
                })
            })
            .collect()
    }

    /// A bind group layout of `entries`, made once per device and kept, so
    /// that the pipelines made for it are found again (`compute_pipelines`).
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn bind_group_layout(&self, label: &str, entries: &[wgpu::BindGroupLayoutEntry]) -> wgpu::BindGroupLayout {
        let mut kernels = self.kernels.lock().unwrap_or_else(|e| e.into_inner());
        kernels
            .layouts
            .entry(entries.to_vec())
            .or_insert_with(|| {
                self.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries })
            })
            .clone()
    }

    /// Opens the adapter that wgpu's environment variables select
    /// (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME`, `WGPU_POWER_PREF`), else the
    /// default one; on a machine with no GPU that is a software adapter.
    /// A software adapter's device is opened with subnormal floats flushed
    /// to zero, as GPUs have them, for the threads it starts; the calling
    /// thread keeps its own floating-point controls.
    pub fn new() -> Result<Gpu, GpuError> {
        pollster::block_on(Self::new_async())
    }

    async fn new_async() -> Result<Gpu, GpuError> {
        // wgpu skips names it does not know, and with none left finds no
        // adapter at all: say which variable is wrong instead
        check_env()?;
        // before the instance enumerates adapters, where the noise comes from
        static QUIET: std::sync::Once = std::sync::Once::new();
        QUIET.call_once(quiet_window_system_probe);
        // wgpu checks the size of every indirect dispatch on the GPU before
        // it runs, with a dispatch of its own: 29 a step at the defaults
        // (the narrowphase's, the contact passes' and the body passes'),
        // about 40 us each on lavapipe (pile-1k stepped 9% faster without). The
        // step's sizes are within max_compute_workgroups_per_dimension by
        // construction (the pairs and manifolds in rows, `write_dispatch` in
        // bindings.wgsl; the listed bodies, `max_bodies`), so the check is off unless
        // WGPU_VALIDATION_INDIRECT_CALL=1 asks for it.
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
        descriptor.flags.remove(wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL);
        let instance = wgpu::Instance::new(descriptor.with_env());
        let adapter = match std::env::var("WGPU_ADAPTER_NAME") {
            Ok(wanted) if !wanted.is_empty() => {
                let adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
                let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
                let lower = wanted.to_lowercase();
                adapters
                    .into_iter()
                    .find(|a| a.get_info().name.to_lowercase().contains(&lower))
                    .ok_or_else(|| GpuError::AdapterNameMismatch(wanted, names.join(", ")))?
            }
            _ => instance
                .request_adapter(&wgpu::RequestAdapterOptions {
                    power_preference: wgpu::PowerPreference::from_env().unwrap_or_default(),
                    force_fallback_adapter: false,
                    compatible_surface: None,
                    ..Default::default()
                })
                .await
                .map_err(|e| GpuError::NoAdapter(format!(" ({e})")))?,
        };
        let info = adapter.get_info();
        let offered = adapter.limits();
        // Ask for what the adapter offers on the limits that bound scene size.
        let limits = wgpu::Limits {
            max_storage_buffer_binding_size: offered.max_storage_buffer_binding_size,
            max_buffer_size: offered.max_buffer_size,
            max_storage_buffers_per_shader_stage: offered.max_storage_buffers_per_shader_stage.min(16),
            max_compute_workgroups_per_dimension: offered.max_compute_workgroups_per_dimension,
            ..wgpu::Limits::default()
        };
        let features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        // a software adapter's threads start as its device opens, with this
        // thread's floating-point controls (subnormals.rs)
        let flush = (info.device_type == wgpu::DeviceType::Cpu).then(subnormals::FlushToZero::begin);
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("verlet"),
                required_features: features,
                required_limits: limits.clone(),
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError::Device(e.to_string()))?;
        drop(flush);
        let errors = std::sync::Arc::new(std::sync::Mutex::new(None));
        let sink = errors.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            if let Ok(mut first) = sink.lock() {
                first.get_or_insert_with(|| e.to_string().replace('\n', " "));
            }
        }));
        let lost = std::sync::Arc::new(std::sync::Mutex::new(None));
        let sink = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut first) = sink.lock() {
                let reason = match reason {
                    wgpu::DeviceLostReason::Destroyed => "the device was destroyed",
                    _ => "the driver gave no reason",
                };
                let message = message.replace('\n', " ");
                first.get_or_insert_with(|| {
                    if message.trim().is_empty() {
                        reason.to_string()
                    } else {
                        format!("{reason}: {message}")
                    }
                });
            }
        });
        static NEXT_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let id = NEXT_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Ok(Gpu {
            adapter,
            device,
            queue,
            info,
            limits,
            errors,
            lost,
            polling: std::sync::Mutex::new(()),
            kernels: std::sync::Mutex::new(Kernels::default()),
            id,
        })
    }

    /// The most loop trips one invocation may take, summed over all of its
    /// loops, where the driver ends its loops past a limit: lavapipe
    /// (llvmpipe) ends every loop of an invocation once their trips sum to
    /// 65535 (gallivm's `LP_MAX_TGSI_LOOP_ITERATIONS`), silently; this
    /// leaves a margin below it. `None` where no such limit is known.
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn loop_trips(&self) -> Option<u32> {
        self.info.name.contains("llvmpipe").then_some(65_000)
    }

    /// A number no other `Gpu` of this process has: whether two are the same.
    pub fn id(&self) -> u64 {
        self.id
    }

    /// One line naming the adapter, its backend and driver.
    pub fn describe(&self) -> String {
        let i = &self.info;
        format!("{} ({:?}, {:?}, driver {} {})", i.name, i.backend, i.device_type, i.driver, i.driver_info)
    }

    /// Submits `commands` to the queue, in turn with other threads' waits
    /// (see `polling`).
    pub fn submit(&self, commands: wgpu::CommandBuffer) {
        let _one_at_a_time = self.polling.lock().unwrap_or_else(|e| e.into_inner());
        self.queue.submit([commands]);
    }

    /// Waits for all submitted work, at most `WAIT_LIMIT`; reports a lost
    /// device, a timeout, or any error the device raised.
    pub fn wait(&self) -> Result<(), GpuError> {
        let started = std::time::Instant::now();
        loop {
            let slice = wgpu::PollType::Wait { submission_index: None, timeout: Some(WAIT_SLICE) };
            let polled = {
                let _one_at_a_time = self.polling.lock().unwrap_or_else(|e| e.into_inner());
                self.device.poll(slice)
            };
            match polled {
                Ok(_) => break,
                Err(wgpu::PollError::Timeout) => {
                    self.check()?;
                    if started.elapsed() >= WAIT_LIMIT {
                        return Err(GpuError::Timeout(WAIT_LIMIT.as_secs()));
                    }
                }
                Err(e) => return Err(GpuError::Runtime(e.to_string())),
            }
        }
        self.check()
    }

    /// The first error the device reported, if any; a lost device first.
    pub fn check(&self) -> Result<(), GpuError> {
        if let Some(why) = self.lost.lock().ok().and_then(|e| e.clone()) {
            return Err(GpuError::Lost(why));
        }
        match self.errors.lock().ok().and_then(|e| e.clone()) {
            Some(e) => Err(GpuError::Runtime(e)),
            None => Ok(()),
        }
    }

    /// Copies `size` bytes of `src` to the host (a blocking readback).
    pub(crate) fn read_buffer(&self, src: &wgpu::Buffer, size: u64) -> Result<Vec<u8>, GpuError> {
        Ok(self.read_buffers(&[(src, size)])?.remove(0))
    }

    /// Copies the first `size` bytes of each buffer to the host, in one
    /// submission and one wait (a blocking readback); each size a multiple
    /// of 4.
    pub(crate) fn read_buffers(&self, sources: &[(&wgpu::Buffer, u64)]) -> Result<Vec<Vec<u8>>, GpuError> {
        let total: u64 = sources.iter().map(|&(_, size)| size).sum();
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: total,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
        let mut at = 0;
        for &(src, size) in sources {
            enc.copy_buffer_to_buffer(src, 0, &staging, at, size);
            at += size;
        }
        self.submit(enc.finish());
        let (tx, rx) = std::sync::mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        // wgpu calls back while polling, so after the wait the answer is in
        // (or never comes, on a broken device: do not block on it)
        rx.recv_timeout(WAIT_SLICE)
            .map_err(|_| GpuError::Runtime("the readback's mapping never completed".into()))?
            .map_err(|e| GpuError::Runtime(e.to_string()))?;
        let bytes = staging.get_mapped_range(..).map_err(|e| GpuError::Runtime(e.to_string()))?.to_vec();
        staging.unmap();
        let mut at = 0;
        Ok(sources
            .iter()
            .map(|&(_, size)| {
                let part = bytes[at as usize..(at + size) as usize].to_vec();
                at += size;
                part
            })
            .collect())
    }
}

/// Keeps a headless run from printing libwayland's `error: XDG_RUNTIME_DIR
/// is invalid or not set in the environment.` (twice) when it opens the
/// GPU. [`Gpu::new`] calls it (once a process), so a program using the
/// library is quiet without knowing of it; calling it first thing in
/// `main` as well is harmless, and the soundest: it may set an environment
/// variable, which is best done while one thread runs.
///
/// Why: wgpu-hal 30 enables every window-system surface extension the
/// Vulkan loader offers (`VK_KHR_wayland_surface` among them,
/// `Instance::desired_extensions`), and offers no option to leave them out
/// (its instance callback may only add extensions). Mesa's implicit
/// `VK_LAYER_MESA_device_select` layer sees that extension and, in each
/// `vkEnumeratePhysicalDevices` (wgpu calls it twice: count, then fill),
/// asks the Wayland compositor which GPU drives the display:
/// `wl_display_connect(NULL)`. With `XDG_RUNTIME_DIR` unset or not an
/// absolute path, and `WAYLAND_DISPLAY` not an absolute path, libwayland
/// prints that line and fails. Exactly then no compositor can be reached
/// anyway, so pointing `WAYLAND_DISPLAY` at `/dev/null`, an absolute path
/// that holds no socket, changes no outcome: libwayland skips the runtime
/// directory, its `connect` fails silently (ECONNREFUSED), and the layer
/// falls back as before (the X server, then the boot VGA device).
///
/// What it costs: nothing is hidden but that line (stderr stays as it
/// is), the variable is set only in that case, and this process's children
/// inherit `WAYLAND_DISPLAY=/dev/null`. A libwayland too old to take an
/// absolute `WAYLAND_DISPLAY` still prints the line (Debian 12's 1.21
/// takes it). Rust's own reads of the environment wait on std's lock while
/// it is set; only C code reading it on another thread at that instant
/// could race, so a program that starts such threads before its first
/// [`Gpu`] calls this first in `main`. Other ways and why not:
/// `NODEVICE_SELECT=1` turns the whole layer off (and with it
/// `MESA_VK_DEVICE_SELECT` and `DRI_PRIME`); a made-up `XDG_RUNTIME_DIR`
/// would have to be created, kept private and removed, and other libraries
/// put files there; filtering stderr would hide other threads' lines.
pub fn quiet_window_system_probe() {
    if cfg!(all(unix, not(target_os = "macos"), not(target_os = "android"))) {
        let absolute = |var: &str| std::env::var_os(var).is_some_and(|v| v.as_encoded_bytes().first() == Some(&b'/'));
        // WAYLAND_SOCKET, an inherited connection, is used without a probe
        let probe_complains =
            std::env::var_os("WAYLAND_SOCKET").is_none() && !absolute("XDG_RUNTIME_DIR") && !absolute("WAYLAND_DISPLAY");
        if probe_complains {
            std::env::set_var("WAYLAND_DISPLAY", "/dev/null");
        }
    }
}

/// The names `WGPU_BACKEND` takes (wgpu_types::Backends::from_comma_list).
const BACKEND_NAMES: &[&str] = &["vulkan", "vk", "dx12", "d3d12", "metal", "mtl", "opengl", "gles", "gl", "webgpu", "noop"];
/// The values `WGPU_POWER_PREF` takes (wgpu_types::PowerPreference::from_env).
const POWER_PREFS: &[&str] = &["low", "high", "none"];

/// Refuses a `WGPU_BACKEND` or `WGPU_POWER_PREF` that wgpu would ignore.
fn check_env() -> Result<(), GpuError> {
    // a value that is not UTF-8 read as unset, and wgpu then used its default
    for name in ["WGPU_BACKEND", "WGPU_POWER_PREF"] {
        if let Some(value) = std::env::var_os(name).filter(|v| v.to_str().is_none()) {
            return Err(GpuError::BadEnv(name, value.to_string_lossy().into_owned(), "text (it is not UTF-8)".into()));
        }
    }
    if let Ok(value) = std::env::var("WGPU_BACKEND") {
        let known = |b: &str| BACKEND_NAMES.contains(&b.trim().to_lowercase().as_str());
        if value.trim().is_empty() || !value.split(',').all(known) {
            let takes = format!("a comma-separated list of: {}", BACKEND_NAMES.join(", "));
            return Err(GpuError::BadEnv("WGPU_BACKEND", value, takes));
        }
        // a backend this build lacks (`gl`) found no adapter, and the error
        // said to install a Vulkan driver
        let built = wgpu::Instance::enabled_backend_features();
        if !wgpu::Backends::from_comma_list(&value).intersects(built) {
            let names: Vec<String> = built.iter_names().map(|(name, _)| name.to_lowercase()).collect();
            let takes = format!("a backend this build has: {}", names.join(", "));
            return Err(GpuError::BadEnv("WGPU_BACKEND", value, takes));
        }
    }
    if let Ok(value) = std::env::var("WGPU_POWER_PREF") {
        // wgpu takes an unknown one as the default; empty reads as unset
        if !value.is_empty() && !POWER_PREFS.contains(&value.to_lowercase().as_str()) {
            return Err(GpuError::BadEnv("WGPU_POWER_PREF", value, format!("one of: {}", POWER_PREFS.join(", "))));
        }
    }
    Ok(())
}

/// GPU timestamps around a run of compute passes: pass k writes queries 2k
/// and 2k + 1, resolved at the end of the encoder and read back as ms.
pub(crate) struct PassTimer {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    passes: u32,
}

impl PassTimer {
    /// Needs `Features::TIMESTAMP_QUERY`.
    pub(crate) fn new(gpu: &Gpu, label: &str, passes: usize) -> PassTimer {
        let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some(label),
            ty: wgpu::QueryType::Timestamp,
            count: 2 * passes as u32,
        });
        let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: 16 * passes as u64,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        PassTimer { set, resolve, passes: passes as u32 }
    }

    /// The timestamp writes of pass `k`.
    pub(crate) fn writes(&self, k: usize) -> wgpu::ComputePassTimestampWrites<'_> {
        wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(2 * k as u32),
            end_of_pass_write_index: Some(2 * k as u32 + 1),
        }
    }

    /// Resolves every pass's queries at the end of `encoder`.
    pub(crate) fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..2 * self.passes, &self.resolve, 0);
    }

    /// Each pass's duration (ms), once the encoder has been submitted.
    pub(crate) fn read_ms(&self, gpu: &Gpu) -> Result<Vec<f64>, GpuError> {
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&gpu.read_buffer(&self.resolve, 16 * self.passes as u64)?);
        let period_ms = gpu.queue.get_timestamp_period() as f64 * 1e-6;
        Ok((0..self.passes as usize).map(|k| ticks[2 * k + 1].saturating_sub(ticks[2 * k]) as f64 * period_ms).collect())
    }
}
