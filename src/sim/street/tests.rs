use super::*;

#[test]
fn default_config_is_valid_and_toml_like_round_trip() {
    let c = StreetConfig::default();
    c.validate().unwrap();
    let json = serde_json::to_string(&c).unwrap();
    let back: StreetConfig = serde_json::from_str(&json).unwrap();
    assert_eq!(back, c);
    let partial: StreetConfig = serde_json::from_str(r#"{"speed": 8.0}"#).unwrap();
    assert_eq!(partial.speed, 8.0);
    assert_eq!(partial.lidar, LidarConfig::default());
    assert!(serde_json::from_str::<StreetConfig>(r#"{"sped": 8.0}"#).is_err());
}
