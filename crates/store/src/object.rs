//! A pyramid in an object store bucket (Amazon S3 or an S3-compatible server: MinIO, Ceph,
//! R2, moto; Google Cloud Storage; Azure Blob Storage): one object per tile and per named
//! file under a key prefix, each written with one PUT, through the `object_store` crate's
//! clients.
//!
//! The [`TileStore`] trait is synchronous; the store owns a small tokio runtime and blocks
//! on it, so it can be called from any thread (rayon's workers, or a thread already inside
//! another tokio runtime, whose future is then driven on a scoped thread instead).
//!
//! # Configuration
//! [`BucketStore::open`] takes `s3://bucket/prefix` (or `s3a://`), `gs://bucket/prefix` or
//! `az://container/prefix` (or `azure://`) and reads everything else from the environment,
//! as `object_store`'s builders' `from_env` do:
//! - **S3**: every `AWS_*` variable the builder knows, among them `AWS_ACCESS_KEY_ID`,
//!   `AWS_SECRET_ACCESS_KEY`, `AWS_SESSION_TOKEN`, `AWS_REGION` (else
//!   `AWS_DEFAULT_REGION`, else `us-east-1`), `AWS_ENDPOINT_URL` (an S3-compatible
//!   server), `AWS_ALLOW_HTTP` (required for an `http://` endpoint),
//!   `AWS_VIRTUAL_HOSTED_STYLE_REQUEST`, `AWS_SKIP_SIGNATURE`,
//!   `AWS_WEB_IDENTITY_TOKEN_FILE` with `AWS_ROLE_ARN`, the container credential variables,
//!   and the client settings `AWS_TIMEOUT` (default 30 s per request) and
//!   `AWS_CONNECT_TIMEOUT` (default 5 s). Without keys it asks the instance metadata
//!   service. `AWS_PROFILE` and `~/.aws/config` / `~/.aws/credentials` are **not** read.
//! - **Google Cloud Storage**: every `GOOGLE_*` variable the builder knows, among them
//!   `GOOGLE_SERVICE_ACCOUNT` (a service account key file) and
//!   `GOOGLE_APPLICATION_CREDENTIALS`; without them, the instance metadata service.
//! - **Azure**: every `AZURE_*` variable the builder knows, among them
//!   `AZURE_STORAGE_ACCOUNT_NAME`, `AZURE_STORAGE_ACCOUNT_KEY`, `AZURE_STORAGE_SAS_KEY`,
//!   `AZURE_CLIENT_ID` / `AZURE_CLIENT_SECRET` / `AZURE_TENANT_ID`, and
//!   `AZURE_STORAGE_USE_EMULATOR` (Azurite on 127.0.0.1:10000).
//!
//! Each client retries as [`retry_config`] says.

use std::future::Future;
use std::sync::Arc;
use std::time::Duration;

use futures_util::TryStreamExt;
use object_store::aws::{AmazonS3Builder, AmazonS3ConfigKey};
use object_store::azure::MicrosoftAzureBuilder;
use object_store::gcp::GoogleCloudStorageBuilder;
use object_store::path::Path as ObjectPath;
use object_store::{
    Attribute, Attributes, BackoffConfig, ClientConfigKey, ObjectStore, ObjectStoreExt, PutOptions,
    PutPayload, RetryConfig,
};

use crate::{
    check_file_name, tile_key, StoreError, StoreResult, TileEncoding, TileStore,
    QUANTIZED_MESH_CONTENT_TYPE,
};

/// The object stores [`BucketStore::open`] reaches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Provider {
    S3,
    Google,
    Azure,
}

impl Provider {
    /// The provider of URL scheme `scheme` (any case): `s3`, `s3a`, `gs`, `az`, `azure`.
    fn of_scheme(scheme: &str) -> Option<Provider> {
        match scheme.to_ascii_lowercase().as_str() {
            "s3" | "s3a" => Some(Provider::S3),
            "gs" => Some(Provider::Google),
            "az" | "azure" => Some(Provider::Azure),
            _ => None,
        }
    }

    /// The scheme the store's URL is written with in messages.
    fn scheme(self) -> &'static str {
        match self {
            Provider::S3 => "s3",
            Provider::Google => "gs",
            Provider::Azure => "az",
        }
    }

    /// The prefix of the environment variables the provider's builder reads.
    fn variables(self) -> &'static str {
        match self {
            Provider::S3 => "AWS_",
            Provider::Google => "GOOGLE_",
            Provider::Azure => "AZURE_",
        }
    }
}

/// How often and how long a failed request is tried again: at most 4 more times, after
/// random waits from 0.1 s up to twice the previous (at most 4 s), and none after 20 s.
/// A server that refuses connections fails a call in under 2 s, one that never answers
/// in at most 20 s plus one request's timeout (`AWS_TIMEOUT`, 30 s by default).
fn retry_config() -> RetryConfig {
    RetryConfig {
        backoff: BackoffConfig {
            init_backoff: Duration::from_millis(100),
            max_backoff: Duration::from_secs(4),
            base: 2.0,
        },
        max_retries: 4,
        retry_timeout: Duration::from_secs(20),
    }
}

/// Whether `destination` names an object store (`s3://...`, `gs://...`, `az://...`) rather
/// than a local path.
pub fn is_object_url(destination: &str) -> bool {
    destination
        .split_once("://")
        .is_some_and(|(scheme, _)| Provider::of_scheme(scheme).is_some())
}

/// Tiles and named files as objects under `prefix` in a bucket. Tiles are stored with
/// `Content-Type: application/vnd.quantized-mesh`, and `Content-Encoding: gzip` when
/// gzipped, so that the bucket can serve them to CesiumJS as they are; `.json` files with
/// `Content-Type: application/json`, 3D Tiles' `.glb` with `model/gltf-binary` and
/// `.subtree` with `application/octet-stream`. Every error names the object's URL.
#[derive(Debug)]
pub struct BucketStore {
    /// `s3://bucket` or `s3://bucket/prefix` (or `gs://`, `az://`), without a trailing `/`.
    url: String,
    store: Arc<dyn ObjectStore>,
    prefix: ObjectPath,
    /// Always `Some` until dropped.
    runtime: Option<tokio::runtime::Runtime>,
}

impl BucketStore {
    /// Deletes the object `relative` under the prefix; no error when there is none.
    fn delete(&self, relative: &str) -> StoreResult<()> {
        let key = self.key(relative);
        match self.block_on(self.store.delete(&key)) {
            Ok(()) | Err(object_store::Error::NotFound { .. }) => Ok(()),
            Err(e) => Err(self.failed(Some(relative), e)),
        }
    }

    /// The store for `url` (`s3://bucket`, `s3://bucket/some/prefix/`, `gs://...`,
    /// `az://container/...`), configured from the environment (see the module
    /// documentation). Nothing is sent to the server: [`BucketStore::probe`] checks that it
    /// can be reached.
    ///
    /// # Errors
    /// [`StoreError::Unusable`] when `url` is not such a URL with a bucket and a valid
    /// prefix, when the environment's settings are invalid or incomplete, or when an S3
    /// endpoint is `http://` without `AWS_ALLOW_HTTP=true`.
    pub fn open(url: &str) -> StoreResult<BucketStore> {
        BucketStore::open_with_env(url, std::env::vars_os())
    }

    /// [`BucketStore::open`] with `vars` in place of the process's environment: the names
    /// the URL's provider reads (`AWS_*`, `GOOGLE_*`, `AZURE_*`) among them are read,
    /// others ignored.
    ///
    /// # Errors
    /// As [`BucketStore::open`].
    pub fn open_with_env<K, V>(
        url: &str,
        vars: impl IntoIterator<Item = (K, V)>,
    ) -> StoreResult<BucketStore>
    where
        K: AsRef<std::ffi::OsStr>,
        V: AsRef<std::ffi::OsStr>,
    {
        let unusable = |reason: String| StoreError::Unusable {
            location: url.to_owned(),
            reason,
        };
        let (provider, rest) = url
            .split_once("://")
            .and_then(|(scheme, rest)| Some((Provider::of_scheme(scheme)?, rest)))
            .ok_or_else(|| unusable("not an s3://, gs:// or az:// URL".into()))?;
        let scheme = provider.scheme();
        let (bucket, prefix) = rest.split_once('/').unwrap_or((rest, ""));
        if bucket.is_empty() {
            return Err(unusable(format!("no bucket name after {scheme}://")));
        }
        let prefix = prefix.trim_end_matches('/');
        let prefix = ObjectPath::parse(prefix)
            .map_err(|e| unusable(format!("the key prefix {prefix:?} is not usable: {e}")))?;
        // As the builders' from_env: the provider's names the builder knows.
        let settings: Vec<(String, String)> = vars
            .into_iter()
            .filter_map(|(key, value)| {
                let key = key.as_ref().to_str()?;
                let value = value.as_ref().to_str()?;
                key.starts_with(provider.variables())
                    .then(|| (key.to_ascii_lowercase(), value.to_owned()))
            })
            .collect();
        // TLS through rustls with ring (the default, aws-lc-rs, adds 1.5 min to a build).
        // The process's default provider: an error means one is installed already.
        let _ = rustls::crypto::ring::default_provider().install_default();
        let bucket_url = format!("{scheme}://{bucket}");
        let store: Arc<dyn ObjectStore> = match provider {
            Provider::S3 => {
                let builder = configured(AmazonS3Builder::new(), &settings, |b, k, v| {
                    b.with_config(k, v)
                })
                .with_url(&bucket_url)
                .with_retry(retry_config());
                check_http_allowed(&builder).map_err(unusable)?;
                Arc::new(builder.build().map_err(|e| unusable(e.to_string()))?)
            }
            Provider::Google => {
                let builder = configured(GoogleCloudStorageBuilder::new(), &settings, |b, k, v| {
                    b.with_config(k, v)
                })
                .with_url(&bucket_url)
                .with_retry(retry_config());
                Arc::new(builder.build().map_err(|e| unusable(e.to_string()))?)
            }
            Provider::Azure => {
                let builder = configured(MicrosoftAzureBuilder::new(), &settings, |b, k, v| {
                    b.with_config(k, v)
                })
                .with_url(&bucket_url)
                .with_retry(retry_config());
                Arc::new(builder.build().map_err(|e| unusable(e.to_string()))?)
            }
        };
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .thread_name("tinsmith-store")
            .enable_all()
            .build()
            .map_err(|e| unusable(format!("cannot start the I/O runtime: {e}")))?;
        let url = if prefix.as_ref().is_empty() {
            bucket_url
        } else {
            format!("{bucket_url}/{prefix}")
        };
        Ok(BucketStore {
            url,
            store,
            prefix,
            runtime: Some(runtime),
        })
    }

    /// Lists at most one page of objects under the prefix, so that a missing bucket, wrong
    /// credentials or an unreachable server are reported before any work is done.
    ///
    /// # Errors
    /// [`StoreError::Io`] naming the store's URL with the server's or the client's reason.
    pub fn probe(&self) -> StoreResult<()> {
        let prefix = (!self.prefix.as_ref().is_empty()).then_some(&self.prefix);
        self.block_on(self.store.list_with_delimiter(prefix))
            .map(|_| ())
            .map_err(|e| self.failed(None, e))
    }

    /// The object key of `relative` (a tile key or a checked file name) under the prefix.
    fn key(&self, relative: &str) -> ObjectPath {
        let mut key = self.prefix.clone();
        key.extend(relative.split('/'));
        key
    }

    /// The URL of `relative` under the prefix, or the store's own, for messages.
    fn url_of(&self, relative: Option<&str>) -> String {
        match relative {
            Some(relative) => format!("{}/{relative}", self.url),
            None => self.url.clone(),
        }
    }

    fn failed(&self, relative: Option<&str>, error: object_store::Error) -> StoreError {
        let kind = match &error {
            object_store::Error::PermissionDenied { .. }
            | object_store::Error::Unauthenticated { .. } => std::io::ErrorKind::PermissionDenied,
            object_store::Error::NotFound { .. } => std::io::ErrorKind::NotFound,
            _ => std::io::ErrorKind::Other,
        };
        StoreError::Io {
            location: self.url_of(relative),
            source: std::io::Error::new(kind, error),
        }
    }

    /// Runs `future` to completion on the store's runtime. From a thread inside some tokio
    /// runtime (where blocking on another would panic) it is driven on a scoped thread.
    fn block_on<F>(&self, future: F) -> F::Output
    where
        F: Future + Send,
        F::Output: Send,
    {
        let runtime = self.runtime.as_ref().expect("the runtime lives until drop");
        if tokio::runtime::Handle::try_current().is_err() {
            return runtime.block_on(future);
        }
        std::thread::scope(|scope| {
            scope
                .spawn(|| runtime.block_on(future))
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
        })
    }

    fn put(&self, relative: &str, bytes: &[u8], attributes: Attributes) -> StoreResult<()> {
        let key = self.key(relative);
        let payload = PutPayload::from(bytes.to_vec());
        self.block_on(
            self.store
                .put_opts(&key, payload, PutOptions::from(attributes)),
        )
        .map(|_| ())
        .map_err(|e| self.failed(Some(relative), e))
    }

    fn get(&self, relative: &str) -> StoreResult<Option<Vec<u8>>> {
        let key = self.key(relative);
        let fetched = self.block_on(async { self.store.get(&key).await?.bytes().await });
        match fetched {
            Ok(bytes) => Ok(Some(bytes.to_vec())),
            Err(object_store::Error::NotFound { .. }) => Ok(None),
            Err(e) => Err(self.failed(Some(relative), e)),
        }
    }
}

/// `builder` with each of `settings` (lower-case variable names) that parses as one of its
/// configuration keys `K`, as the builders' `from_env` take them; others are ignored.
fn configured<B, K: std::str::FromStr>(
    mut builder: B,
    settings: &[(String, String)],
    with_config: impl Fn(B, K, &str) -> B,
) -> B {
    for (key, value) in settings {
        if let Ok(key) = key.parse() {
            builder = with_config(builder, key, value);
        }
    }
    builder
}

/// Refuses an `http://` endpoint unless `AWS_ALLOW_HTTP` is true, with a message that says
/// so (the client's own is "URL scheme is not allowed", from deep inside a retry).
fn check_http_allowed(builder: &AmazonS3Builder) -> Result<(), String> {
    let endpoint = builder
        .get_config_value(&AmazonS3ConfigKey::Endpoint)
        .unwrap_or_default();
    if !endpoint.to_ascii_lowercase().starts_with("http://") {
        return Ok(());
    }
    let allowed = builder
        .get_config_value(&AmazonS3ConfigKey::Client(ClientConfigKey::AllowHttp))
        .is_some_and(|v| {
            matches!(
                v.trim().to_ascii_lowercase().as_str(),
                "1" | "true" | "on" | "yes" | "y"
            )
        });
    if allowed {
        Ok(())
    } else {
        Err(format!(
            "the endpoint {endpoint} is plain HTTP: set AWS_ALLOW_HTTP=true to allow it"
        ))
    }
}

impl Drop for BucketStore {
    fn drop(&mut self) {
        // Never blocks, and never panics inside another runtime as a plain drop would.
        if let Some(runtime) = self.runtime.take() {
            runtime.shutdown_background();
        }
    }
}

impl TileStore for BucketStore {
    fn location(&self) -> String {
        self.url.clone()
    }

    fn put_tile(
        &self,
        z: u8,
        x: u32,
        y: u32,
        bytes: &[u8],
        encoding: TileEncoding,
    ) -> StoreResult<()> {
        let mut attributes = Attributes::new();
        attributes.insert(Attribute::ContentType, QUANTIZED_MESH_CONTENT_TYPE.into());
        if encoding == TileEncoding::Gzip {
            attributes.insert(Attribute::ContentEncoding, "gzip".into());
        }
        self.put(&tile_key(z, x, y), bytes, attributes)
    }

    fn get_tile(&self, z: u8, x: u32, y: u32) -> StoreResult<Option<Vec<u8>>> {
        self.get(&tile_key(z, x, y))
    }

    fn delete_tile(&self, z: u8, x: u32, y: u32) -> StoreResult<()> {
        self.delete(&tile_key(z, x, y))
    }

    fn delete_file(&self, name: &str) -> StoreResult<()> {
        check_file_name(name)?;
        self.delete(name)
    }

    fn put_file(&self, name: &str, bytes: &[u8]) -> StoreResult<()> {
        check_file_name(name)?;
        let mut attributes = Attributes::new();
        let content_type = match name.rsplit_once('.').map(|(_, e)| e) {
            Some("json") => Some("application/json"),
            Some("glb") => Some("model/gltf-binary"),
            Some("subtree") => Some("application/octet-stream"),
            _ => None,
        };
        if let Some(content_type) = content_type {
            attributes.insert(Attribute::ContentType, content_type.into());
        }
        self.put(name, bytes, attributes)
    }

    fn get_file(&self, name: &str) -> StoreResult<Option<Vec<u8>>> {
        check_file_name(name)?;
        self.get(name)
    }

    fn list_files(&self, prefix: &str) -> StoreResult<Vec<String>> {
        // Object stores list whole path segments: list the directory part of the prefix,
        // then keep the names that start with all of it.
        let dir = prefix.rsplit_once('/').map_or("", |(dir, _)| dir);
        let base = if dir.is_empty() {
            self.prefix.clone()
        } else {
            check_file_name(dir)?;
            self.key(dir)
        };
        let listed: Vec<_> = self
            .block_on(self.store.list(Some(&base)).try_collect())
            .map_err(|e| self.failed((!dir.is_empty()).then_some(dir), e))?;
        let mut names: Vec<String> = listed
            .iter()
            .filter_map(|meta| {
                let parts: Vec<_> = meta.location.prefix_match(&self.prefix)?.collect();
                Some(
                    parts
                        .iter()
                        .map(|p| p.as_ref())
                        .collect::<Vec<_>>()
                        .join("/"),
                )
            })
            .filter(|name| name.starts_with(prefix))
            .collect();
        names.sort();
        Ok(names)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NO_VARS: [(&str, &str); 0] = [];

    #[test]
    fn only_object_store_urls_with_a_bucket_open() {
        assert!(is_object_url("s3://b/p"));
        assert!(is_object_url("S3A://b"));
        assert!(is_object_url("gs://b/p"));
        assert!(is_object_url("azure://c"));
        assert!(!is_object_url("out/pyramid"));
        assert!(!is_object_url("/vsis3/b/k"));
        assert!(!is_object_url("file:///tmp/x"));
        assert!(!is_object_url("gcs://b/p"));
        for bad in [
            "s3://",
            "s3:///prefix",
            "out/dir",
            "gcs://b/p",
            "s3://b/a//c",
            "gs://",
            "az://c/a//b",
        ] {
            let e = BucketStore::open_with_env(bad, NO_VARS).unwrap_err();
            assert!(
                matches!(e, StoreError::Unusable { ref location, .. } if location == bad),
                "{bad}: {e}"
            );
        }
    }

    #[test]
    fn keys_and_urls_sit_under_the_prefix() {
        let store = BucketStore::open_with_env("s3://bucket/a/b/", NO_VARS).unwrap();
        assert_eq!(store.location(), "s3://bucket/a/b");
        assert_eq!(store.key(&tile_key(3, 1, 2)).as_ref(), "a/b/3/1/2.terrain");
        assert_eq!(store.key("layer.json").as_ref(), "a/b/layer.json");
        assert_eq!(
            store.url_of(Some("layer.json")),
            "s3://bucket/a/b/layer.json"
        );
        let root = BucketStore::open_with_env("s3://bucket", NO_VARS).unwrap();
        assert_eq!(root.location(), "s3://bucket");
        assert_eq!(root.key("shards/1.json").as_ref(), "shards/1.json");
    }

    #[test]
    fn plain_http_needs_allow_http() {
        let endpoint = [("AWS_ENDPOINT_URL", "http://127.0.0.1:9")];
        let e = BucketStore::open_with_env("s3://b/p", endpoint).unwrap_err();
        assert!(e.to_string().contains("AWS_ALLOW_HTTP"), "{e}");
        let allowed = [endpoint[0], ("AWS_ALLOW_HTTP", "true")];
        BucketStore::open_with_env("s3://b/p", allowed).unwrap();
    }

    #[test]
    fn usable_from_inside_another_runtime() {
        // Nothing listens on port 9 of the loopback: the call must fail, not panic
        // ("Cannot start a runtime from within a runtime").
        let vars = [
            ("AWS_ENDPOINT_URL", "http://127.0.0.1:9"),
            ("AWS_ALLOW_HTTP", "true"),
            ("AWS_ACCESS_KEY_ID", "k"),
            ("AWS_SECRET_ACCESS_KEY", "s"),
        ];
        let store = BucketStore::open_with_env("s3://bucket/p", vars).unwrap();
        let outer = tokio::runtime::Builder::new_current_thread()
            .build()
            .unwrap();
        let got = outer.block_on(async { store.get_file("layer.json") });
        let e = got.unwrap_err().to_string();
        assert!(e.contains("s3://bucket/p/layer.json"), "{e}");
        // Dropped inside the other runtime: no panic either.
        outer.block_on(async { drop(store) });
    }

    #[test]
    fn a_server_that_never_answers_fails_in_bounded_time() {
        // Connections are accepted (by the kernel, into the backlog) and never answered.
        let silent = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let endpoint = format!("http://{}", silent.local_addr().unwrap());
        let vars = [
            ("AWS_ENDPOINT_URL", endpoint.as_str()),
            ("AWS_ALLOW_HTTP", "true"),
            ("AWS_ACCESS_KEY_ID", "k"),
            ("AWS_SECRET_ACCESS_KEY", "s"),
            ("AWS_TIMEOUT", "500ms"),
        ];
        let store = BucketStore::open_with_env("s3://bucket/slow", vars).unwrap();
        let started = std::time::Instant::now();
        let e = store
            .put_tile(0, 0, 0, b"x", TileEncoding::Gzip)
            .unwrap_err()
            .to_string();
        let took = started.elapsed();
        assert!(took < Duration::from_secs(15), "took {took:?}: {e}");
        assert!(e.contains("s3://bucket/slow/0/0/0.terrain"), "{e}");
        drop(silent);
    }
}
