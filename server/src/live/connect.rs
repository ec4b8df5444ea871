//! How the two live doors (`semo operator`, the editor's monitor) reach a
//! mission's broker, once: the address (`mqtt://` or `mqtts://`, read by
//! `semo::deploy::broker_address` as deployment files are), the operator's
//! user and password, and for `mqtts://` the TLS configuration from the
//! deployment file's operator (its `ca`, else the file's; its client
//! certificate and key), on rustls with the `ring` provider. And what a
//! failed connection means, said so that the user can act: a broker
//! certificate that the CA does not vouch for will not fix itself by
//! trying again, a broker that is down may.

use rumqttc::{ConnectionError, MqttOptions, TlsConfiguration, Transport};
use rustls::pki_types::pem::PemObject;
use rustls::pki_types::{CertificateDer, PrivateKeyDer};
use semo::deploy::Deployment;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where the broker is and how to log in to it.
#[derive(Clone)]
pub struct BrokerAccess {
    /// The broker URL as given.
    pub url: String,
    pub host: String,
    pub port: u16,
    /// The operator's user and password (the first line of its file).
    pub credentials: Option<(String, String)>,
    /// `mqtts://`: the CA file the broker's certificate is checked with.
    pub ca: Option<PathBuf>,
    tls: Option<Arc<rustls::ClientConfig>>,
}

impl std::fmt::Debug for BrokerAccess {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Never the password.
        f.debug_struct("BrokerAccess")
            .field("url", &self.url)
            .field("user", &self.credentials.as_ref().map(|(user, _)| user))
            .field("ca", &self.ca)
            .finish()
    }
}

/// A connection that failed, as the user should read it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    pub message: String,
    /// Trying again cannot help (the TLS handshake failed: a certificate
    /// not trusted, refused or not for this host) until a file or the
    /// broker's configuration changes.
    pub permanent: bool,
}

impl BrokerAccess {
    /// The access to `url` as the deployment's operator (anonymous without
    /// a deployment or an `[operator]` user). The deployment's files were
    /// checked when it was read (E123, E126); what still fails here (a
    /// password file gone meanwhile, a certificate rustls cannot use) is
    /// said with the file's path.
    pub fn new(url: &str, deployment: Option<&Deployment>) -> Result<BrokerAccess, String> {
        let operator = deployment
            .map(Deployment::operator_credentials)
            .unwrap_or_default();
        BrokerAccess::as_client(url, &operator, "the operator", deployment.is_some())
    }

    /// The access to `url` as robot `robot` of team `team` with its
    /// credentials from the deployment (`semo gateway` speaks for it): its
    /// entry's over its team's over the file's, as `semo build --deploy`
    /// bakes them into a Linux robot.
    pub fn robot(
        url: &str,
        deployment: Option<&Deployment>,
        team: &str,
        robot: &str,
    ) -> Result<BrokerAccess, String> {
        let credentials = deployment
            .map(|d| d.robot(team, robot).credentials)
            .unwrap_or_default();
        BrokerAccess::as_client(
            url,
            &credentials,
            &format!("robot `{robot}`"),
            deployment.is_some(),
        )
    }

    /// The access to `url` as the client `who` with `operator`'s credentials.
    fn as_client(
        url: &str,
        operator: &semo::deploy::Credentials,
        who: &str,
        deployed: bool,
    ) -> Result<BrokerAccess, String> {
        let address = semo::deploy::broker_address(url)?;
        let credentials = match &operator.user {
            None => None,
            Some(user) => {
                let password = match &operator.password_file {
                    None => String::new(),
                    Some(path) => semo::workspace::read_text(path)
                        .map_err(|e| {
                            format!("cannot read {who}'s password file {}: {e}", path.display())
                        })?
                        .lines()
                        .next()
                        .unwrap_or("")
                        .to_string(),
                };
                Some((user.clone(), password))
            }
        };
        let (ca, tls) = if address.tls {
            let Some(ca) = operator.ca.clone() else {
                return Err(format!(
                    "{url} is a TLS broker: its certificate is checked with the CA of the deployment file (`ca` at its top, or {who}'s own), {}",
                    if deployed {
                        "which names none"
                    } else {
                        "and none is given (--deploy FILE, or the project's `[build] deployment`)"
                    }
                ));
            };
            let client = operator.cert.as_deref().zip(operator.key.as_deref());
            let config = tls_config(&ca, client)?;
            (Some(ca), Some(config))
        } else {
            (None, None)
        };
        Ok(BrokerAccess {
            url: url.to_string(),
            host: address.host,
            port: address.port,
            credentials,
            ca,
            tls,
        })
    }

    /// Whether the broker is reached with TLS.
    pub fn is_tls(&self) -> bool {
        self.tls.is_some()
    }

    /// rumqttc's options for a client `client_id` of this broker.
    pub fn options(&self, client_id: String) -> MqttOptions {
        let mut options = MqttOptions::new(client_id, self.host.clone(), self.port);
        if let Some((user, password)) = &self.credentials {
            options.set_credentials(user.clone(), password.clone());
        }
        if let Some(config) = &self.tls {
            options.set_transport(Transport::tls_with_config(TlsConfiguration::Rustls(
                config.clone(),
            )));
        }
        options
    }

    /// What `error` (a failed connection to this broker) means.
    pub fn failure(&self, error: &ConnectionError) -> Failure {
        let Some(tls) = rustls_error(error) else {
            return Failure {
                message: format!("{} ({error})", self.url),
                permanent: false,
            };
        };
        use rustls::{CertificateError, Error};
        let ca = self
            .ca
            .as_ref()
            .map_or("(none)".to_string(), |p| p.display().to_string());
        let message = match tls {
            Error::InvalidCertificate(
                CertificateError::NotValidForName | CertificateError::NotValidForNameContext { .. },
            ) => format!(
                "the broker's certificate is not for {} ({tls}): the broker URL must name a host or address its certificate names",
                self.host
            ),
            Error::InvalidCertificate(
                CertificateError::Expired
                | CertificateError::ExpiredContext { .. }
                | CertificateError::NotValidYet
                | CertificateError::NotValidYetContext { .. },
            ) => format!("the broker's certificate is not valid now ({tls})"),
            Error::InvalidCertificate(_) => format!(
                "the broker's certificate is not trusted: the CA {ca} (the deployment's `ca`) does not vouch for it ({tls})"
            ),
            Error::AlertReceived(_) => format!(
                "the broker refused the TLS handshake ({tls}): it wants a client certificate its CA signed ([operator] `cert` and `key` of the deployment file)"
            ),
            _ => format!(
                "TLS with {} failed ({tls}): is it a TLS listener?",
                self.url
            ),
        };
        Failure {
            message,
            permanent: true,
        }
    }
}

/// The rustls error under a failed connection, if TLS failed: in the
/// handshake (tokio-rustls hands it over inside an I/O error) or at the
/// first read after it (a TLS 1.3 server refuses a client certificate
/// then: rumqttc wraps it as a read error of its state machine).
fn rustls_error(error: &ConnectionError) -> Option<&rustls::Error> {
    let mut next: Option<&(dyn std::error::Error + 'static)> = Some(error);
    while let Some(e) = next {
        if let Some(tls) = e.downcast_ref::<rustls::Error>() {
            return Some(tls);
        }
        // An I/O error's `source` skips the error it carries.
        next = match e
            .downcast_ref::<std::io::Error>()
            .and_then(|io| io.get_ref())
        {
            Some(inner) => Some(inner),
            None => e.source(),
        };
    }
    None
}

/// The client's TLS configuration: the broker's certificate checked with the
/// CAs of `ca`, and the client certificate and key when given.
fn tls_config(
    ca: &Path,
    client: Option<(&Path, &Path)>,
) -> Result<Arc<rustls::ClientConfig>, String> {
    let mut roots = rustls::RootCertStore::empty();
    let (added, _unusable) = roots.add_parsable_certificates(certificates(ca, "CA")?);
    if added == 0 {
        return Err(format!(
            "the CA file {} holds no certificate that can be used",
            ca.display()
        ));
    }
    let provider = Arc::new(rustls::crypto::ring::default_provider());
    let builder = rustls::ClientConfig::builder_with_provider(provider)
        .with_safe_default_protocol_versions()
        .map_err(|e| format!("TLS: {e}"))?
        .with_root_certificates(roots);
    let config = match client {
        None => builder.with_no_client_auth(),
        Some((cert, key)) => {
            let chain = certificates(cert, "client certificate")?;
            let text = read(key, "client key")?;
            let key_der = PrivateKeyDer::from_pem_slice(text.as_bytes()).map_err(|e| {
                format!(
                    "the client key {} holds no PEM private key: {e}",
                    key.display()
                )
            })?;
            builder.with_client_auth_cert(chain, key_der).map_err(|e| {
                format!(
                    "the client certificate {} and key {} cannot be used: {e}",
                    cert.display(),
                    key.display()
                )
            })?
        }
    };
    Ok(Arc::new(config))
}

fn read(path: &Path, what: &str) -> Result<String, String> {
    semo::workspace::read_text(path)
        .map_err(|e| format!("cannot read the {what} {}: {e}", path.display()))
}

/// The PEM certificates of a file (at least one).
fn certificates(path: &Path, what: &str) -> Result<Vec<CertificateDer<'static>>, String> {
    let text = read(path, what)?;
    let found = CertificateDer::pem_slice_iter(text.as_bytes())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| format!("the {what} {} is not valid PEM: {e}", path.display()))?;
    if found.is_empty() {
        return Err(format!(
            "the {what} {} holds no PEM certificate",
            path.display()
        ));
    }
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_and_anonymous_without_a_deployment() {
        let access = BrokerAccess::new("mqtt://h:99", None).unwrap();
        assert_eq!((access.host.as_str(), access.port), ("h", 99));
        assert!(access.credentials.is_none() && !access.is_tls());
        assert!(BrokerAccess::new("tcp://h", None).is_err());
        // A TLS broker needs the deployment's CA: refused, not connected
        // without checking the broker.
        let refused = BrokerAccess::new("mqtts://h", None).unwrap_err();
        assert!(refused.contains("is a TLS broker"), "{refused}");
    }

    #[test]
    fn a_ca_that_rustls_cannot_use_is_refused_with_its_path() {
        let dir = tempfile::tempdir().unwrap();
        // Valid PEM, but no certificate inside.
        let ca = dir.path().join("ca.crt");
        std::fs::write(
            &ca,
            "-----BEGIN CERTIFICATE-----\nMIIBAA==\n-----END CERTIFICATE-----\n",
        )
        .unwrap();
        let deploy = dir.path().join("d.deploy.toml");
        std::fs::write(&deploy, "broker = \"mqtts://127.0.0.1\"\nca = \"ca.crt\"\n").unwrap();
        let deployment = semo::deploy::load(&deploy, semo::diag::FileId(0)).unwrap();
        let refused = BrokerAccess::new(&deployment.broker.url, Some(&deployment)).unwrap_err();
        assert!(
            refused.contains("holds no certificate that can be used") && refused.contains("ca.crt"),
            "{refused}"
        );
    }
}
