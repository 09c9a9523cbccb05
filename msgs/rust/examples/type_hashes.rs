//! Prints every type hash this crate computed, one `type_name hash` a line (the tests compare
//! them with the type-description JSON files rosidl generates).
fn main() {
    for (name, hash) in mobil_msgs::TYPE_HASHES {
        println!("{name} {hash}");
    }
}
